//! A shaded or gradient-weighted bricked frame's voxel differences (`BrickStore::gradient_words`):
//! `brick_params` and `brick_pyramid` read one voxel's two words instead of its six neighbours
//! through the store.
use super::*;
use crate::bricks::BrickScene;

/// Make the two buffers hold this classification's differences (`bytes`: both), made on its first
/// frame (the 512³ bonsai: ~0.2 s, the `gradients` time).
pub(super) fn upload(e: &mut dyn Engine, scene: &BrickScene, bytes: u64) -> Result<()> {
    let res = [Res::BrickGradients, Res::BrickGradientsHi];
    let id = scene.classification();
    for r in res {
        e.ensure(r, bytes / 2)?;
    }
    if res.iter().any(|&r| e.tag(r) != id) {
        let t = std::time::Instant::now();
        for (r, words) in res.into_iter().zip(scene.gradient_words()) {
            e.upload(r, &words)?;
            e.set_tag(r, id);
        }
        e.host_time("gradients", t.elapsed().as_secs_f64() * 1e3);
    }
    Ok(())
}
