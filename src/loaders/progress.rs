//! How far a long load has come, told to the caller (a progress bar, a viewer's status line).
use std::sync::Arc;

/// Called as `BrickStore::load` streams a file (`VolumeHints::progress`): with the slices read so
/// far and the slices it reads in all, which counts the file twice when its samples cannot be
/// kept between the value range's pass and the bricks' (`bricks::SLAB_CACHE_BYTES`). A file
/// loaded whole first (`.npy`) tells nothing. Clones share one callback.
#[derive(Clone)]
pub struct Progress(Arc<dyn Fn(u64, u64) + Send + Sync>);

impl Progress {
    /// `report(read, of)` after each slab read.
    pub fn new(report: impl Fn(u64, u64) + Send + Sync + 'static) -> Self {
        Progress(Arc::new(report))
    }

    /// Report `read` of `of` (as the loader does after each slab).
    pub fn report(&self, read: u64, of: u64) {
        (self.0)(read, of)
    }

    pub(crate) fn as_fn(&self) -> &dyn Fn(u64, u64) {
        &*self.0
    }
}

impl std::fmt::Debug for Progress {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Progress")
    }
}
