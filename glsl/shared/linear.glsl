// 1D dispatches larger than one row of workgroups wrap into gl_WorkGroupID.y (see groups_1d in
// src/plan.rs). Compute stages with local_size_x = WORKGROUP_SIZE only.
uint linear_invocation() {
    return gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * WORKGROUP_SIZE;
}
