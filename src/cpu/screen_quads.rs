//! Mirror of `glsl/screen_quads.comp` (the `screen_quads` stage); shared helpers in `tile.rs`.
use super::bindings::Bindings;
use super::footprint::FootprintInputs;
use super::tile::screen_record;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::{FootprintPush, ScreenQuad};

/// Each of the list's `push.count` entries' footprint in screen space, at its splat's index.
pub fn screen_quads(inputs: &FootprintInputs<'_>, push: &FootprintPush, quads: &mut [ScreenQuad]) {
    for &splat in &inputs.draw_list[..push.count as usize] {
        quads[splat as usize] = screen_record(inputs.frame, &inputs.params[splat as usize]);
    }
}

pub(crate) fn stage(b: &mut Bindings<'_>, d: &Args, _: &Variant) -> Result<()> {
    let mut quads = b.take(Res::Quads);
    screen_quads(&b.inputs(d.list), &d.push_as(), bytemuck::cast_slice_mut(&mut quads));
    b.put(Res::Quads, quads);
    Ok(())
}
