//! A volume over time: each time point swapped into the renderer's bricked scene
//! (`Renderer::update_volume`), the device rewriting only the bricks that changed.
use crate::bricks::BrickStore;
use crate::error::{Error, Result};
use crate::plan::Prepared;
use crate::Renderer;

/// What `Renderer::update_volume` changed.
///
/// ```
/// use voxsplat::{bricks::BrickStore, classify::TransferFunction, loaders::ScalarVolume};
/// use voxsplat::{Backend, Renderer, RendererOptions};
/// let mut o = RendererOptions::default();
/// o.backend = Backend::Cpu;
/// let mut r = Renderer::new(&o)?;
/// let values = (0..16 * 16 * 16).map(|i| (i % 16) as f32 / 15.0).collect();
/// let volume = ScalarVolume { dims: [16; 3], spacing: [1.0; 3], values };
/// r.set_volume(&volume, &TransferFunction::preset("ramp")?, None)?;
/// // The same voxels again: no brick changed.
/// let update = r.update_volume(BrickStore::build(&volume)?)?;
/// assert_eq!(update.changed, 0);
/// # Ok::<(), voxsplat::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct VolumeUpdate {
    /// Bricks whose voxels changed, appeared or went empty.
    pub changed: usize,
    /// Non-empty bricks of the new time point.
    pub bricks: usize,
    /// Bytes written to the device's store (0 on the CPU backend).
    pub uploaded: u64,
    /// Bytes the store takes on a device (`BrickStore::bytes`): what `set_volume` uploads.
    pub store_bytes: u64,
    /// Whether the set of non-empty bricks changed (the headers, masks and index were rewritten
    /// whole).
    pub layout: bool,
}

impl Renderer {
    /// Make `store` the bricked scene's next time point, classified as the scene is: the same
    /// grid, normalised by the same range (build it with `BrickStore::from_region(.., range, ..)`
    /// or `BrickStore::load_in_range`). The device keeps its pipelines, frame buffers and the
    /// records of every brick that did not change; the changed bricks are written in place
    /// (`BrickStore::patch`). What the frame derives from the values (the level-of-detail
    /// pyramid, a shaded frame's gradients, the ray caster's field) is derived again on the next
    /// frame. Refused, with the scene kept, when the grid or the range differ; when the device
    /// fails while it is written (out of memory), the renderer is left without a scene.
    ///
    /// ```
    /// use voxsplat::bricks::BrickStore;
    /// use voxsplat::classify::TransferFunction;
    /// use voxsplat::volume::ScalarVolume;
    /// use voxsplat::{Backend, Renderer, RendererOptions};
    /// // Two time points of a 32³ volume: a block that moves by one voxel along x, beside one
    /// // that stays.
    /// let at = |t: u32| {
    ///     let (x, y) = (|i: u32| i % 32, |i: u32| i / 32 % 32);
    ///     let moving = |i| (10 + t..20 + t).contains(&x(i)) && (10..20).contains(&y(i));
    ///     let still = |i| x(i) >= 24 && y(i) >= 24;
    ///     let values = (0..32 * 32 * 32u32).map(|i| if moving(i) || still(i) { 1.0 } else { 0.0 }).collect();
    ///     ScalarVolume { dims: [32; 3], spacing: [1.0; 3], values }
    /// };
    /// let mut options = RendererOptions::default();
    /// options.backend = Backend::Cpu;
    /// let mut renderer = Renderer::new(&options)?;
    /// renderer.set_volume(&at(0), &TransferFunction::preset("ramp")?, None)?;
    /// let range = renderer.volume().unwrap().store.range;
    /// let next = at(1);
    /// let plane = 32 * 32;
    /// let store = BrickStore::from_region(next.dims, next.spacing, range, [[0; 3], next.dims], |z0, n, out| {
    ///     out.clear();
    ///     out.extend_from_slice(&next.values[z0 as usize * plane..(z0 + n) as usize * plane]);
    ///     Ok(())
    /// })?;
    /// let update = renderer.update_volume(store)?;
    /// assert!(update.changed > 0 && update.changed < update.bricks);
    /// # Ok::<(), voxsplat::Error>(())
    /// ```
    pub fn update_volume(&mut self, store: BrickStore) -> Result<VolumeUpdate> {
        let needs = || Error::InvalidArgument("update_volume needs a bricked volume (Renderer::set_volume)".into());
        let prep = self.scene.as_mut().ok_or_else(needs)?;
        let mut scene = prep.bricks.take().ok_or_else(needs)?;
        let patch = match scene.update(store) {
            Ok(p) => p,
            Err(e) => {
                prep.bricks = Some(scene);
                return Err(e);
            }
        };
        let (bricks, store_bytes) = (scene.store.headers.len(), scene.store.bytes());
        // The scene's fields (the ray caster's, the isosurface's) were made from the old values.
        let next = Prepared::bricked(scene).and_then(|next| match &mut self.gpu {
            Some(g) => g.patch_store(&next, &patch).map(|sent| (next, sent)),
            None => Ok((next, 0)),
        });
        match next {
            Ok((next, uploaded)) => {
                *prep = next;
                Ok(VolumeUpdate { changed: patch.changed, bricks, uploaded, store_bytes, layout: patch.layout })
            }
            Err(e) => {
                // The device holds part of the new time point: no scene rather than a wrong frame.
                self.scene = None;
                Err(e)
            }
        }
    }
}
