#version 450
// Roofline fragment: an additive Gaussian weight, nothing else.
layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

void main() {
    float w = exp(-4.0 * dot(in_uv, in_uv));
    out_color = vec4(w, w, w, w);
}
