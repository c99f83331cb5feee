use ash::vk;

/// Everything that can go wrong, split by concern so callers can tell their input from the device.
///
/// ```
/// use voxsplat::{Camera, Error, Grid};
/// let grid = Grid::centered([8; 3], [1.0; 3])?;
/// let mut camera = Camera::framing(&grid, 64, 64);
/// camera.target = camera.eye; // no view direction
/// match camera.validate() {
///     Err(Error::InvalidCamera(why)) => eprintln!("fix the camera: {why}"),
///     other => panic!("{other:?}"),
/// }
/// # Ok::<(), voxsplat::Error>(())
/// ```
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A bad argument: NaN, zero size, unknown name, out-of-range value.
    #[error("invalid argument: {0}")]
    InvalidArgument(String),
    /// The camera cannot form a view (eye at target, up parallel to the view, bad angles).
    #[error("invalid camera: {0}")]
    InvalidCamera(String),
    /// The scene exceeds a configured limit.
    #[error("scene too large: {0}")]
    TooLarge(String),
    /// No usable Vulkan device or a missing feature / layer.
    #[error("unsupported: {0}")]
    Unsupported(String),
    /// Device or host memory ran out.
    #[error("out of memory while allocating {0}")]
    OutOfMemory(String),
    /// The device was lost (driver reset, hang or crash). Every later GPU call on this renderer
    /// fails the same way; drop it and create a new one.
    #[error("the Vulkan device was lost during {0}; drop this renderer and create a new one")]
    DeviceLost(String),
    /// A Vulkan call failed.
    #[error("Vulkan call {call} failed: {result}")]
    Vulkan {
        /// The Vulkan function.
        call: &'static str,
        /// What it returned.
        result: vk::Result,
    },
    /// The Vulkan loader could not be opened.
    #[error("cannot load Vulkan: {0}")]
    Loader(String),
    /// Reading or writing a file.
    #[error("I/O error on {path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// Decoding an input image (PNG, EXR).
    #[error("cannot read image {path}: {message}")]
    ImageRead {
        /// The file.
        path: String,
        /// The decoder's message.
        message: String,
    },
    /// An error on one rank of a distributed render, which every rank returns (`distributed`).
    #[error("rank {rank} of {ranks}: {source}")]
    OnRank {
        /// The rank it happened on (the lowest, when several failed).
        rank: u32,
        /// The ranks rendering.
        ranks: u32,
        /// What went wrong there.
        source: Box<Error>,
    },
    /// Encoding an output image.
    #[error("cannot write image {path}: {message}")]
    Image {
        /// The file.
        path: String,
        /// The encoder's message.
        message: String,
    },
}

/// Longest message a decoder may put in an error: a corrupt file can make a decoder describe
/// itself at length (one flipped bit in a TIFF gave 315,815 bytes).
#[cfg(feature = "io")]
const MAX_MESSAGE: usize = 400;

/// `message`, cut at `MAX_MESSAGE` bytes with a note of how much was left out.
#[cfg(feature = "io")]
pub(crate) fn clip_message(message: impl std::fmt::Display) -> String {
    let mut m = message.to_string();
    if m.len() > MAX_MESSAGE {
        let cut = (0..=MAX_MESSAGE).rev().find(|&i| m.is_char_boundary(i)).unwrap_or(0);
        let left = m.len() - cut;
        m.truncate(cut);
        m.push_str(&format!("... ({left} more bytes)"));
    }
    m
}

/// The crate's result type.
///
/// ```
/// fn frame_size() -> voxsplat::Result<u32> {
///     let grid = voxsplat::Grid::centered([0, 4, 4], [1.0; 3])?; // refused: an empty side
///     Ok(grid.dims[0])
/// }
/// assert!(frame_size().is_err());
/// ```
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    pub(crate) fn vk(call: &'static str) -> impl FnOnce(vk::Result) -> Error {
        move |result| match result {
            vk::Result::ERROR_OUT_OF_DEVICE_MEMORY | vk::Result::ERROR_OUT_OF_HOST_MEMORY => {
                Error::OutOfMemory(call.to_string())
            }
            vk::Result::ERROR_DEVICE_LOST => Error::DeviceLost(call.to_string()),
            result => Error::Vulkan { call, result },
        }
    }
}

/// The process's host-memory budget in bytes (`set_host_budget`); `u64::MAX`: none set.
static HOST_BUDGET: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(u64::MAX);

/// The share of physical memory the host budget takes when none is set: 3/4, which leaves the
/// rest to the system and to what the budget does not size (the device's driver, buffers).
pub const DEFAULT_HOST_SHARE: (u64, u64) = (3, 4);

/// Cap the host memory that allocations sized by a file's header or a caller's request may take
/// (`check_host_memory`), below what the host has available; `None` restores the default
/// (`DEFAULT_HOST_SHARE` of physical memory).
pub fn set_host_budget(bytes: Option<u64>) {
    HOST_BUDGET.store(bytes.unwrap_or(u64::MAX), std::sync::atomic::Ordering::Relaxed);
}

/// The host-memory budget in force: the one `set_host_budget` set, else `DEFAULT_HOST_SHARE` of
/// the host's physical memory (Linux's MemTotal; `None` where the host does not say).
pub fn host_budget() -> Option<u64> {
    let set = HOST_BUDGET.load(std::sync::atomic::Ordering::Relaxed);
    if set != u64::MAX {
        return Some(set);
    }
    physical_memory().map(|m| m / DEFAULT_HOST_SHARE.1 * DEFAULT_HOST_SHARE.0)
}

/// Physical memory in bytes, read once (Linux's MemTotal).
fn physical_memory() -> Option<u64> {
    static TOTAL: std::sync::OnceLock<Option<u64>> = std::sync::OnceLock::new();
    *TOTAL.get_or_init(|| meminfo("MemTotal:"))
}

/// A /proc/meminfo field in bytes.
fn meminfo(field: &str) -> Option<u64> {
    let m = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = m.lines().find(|l| l.starts_with(field))?;
    line.split_whitespace().nth(1)?.parse::<u64>().ok().map(|kb| kb * 1024)
}

/// Refuse `bytes` of host memory for `what` past the host budget (`host_budget`) or when the
/// host has less available (Linux's MemAvailable; elsewhere only the budget is checked).
pub fn check_host_memory(bytes: u64, what: &str) -> Result<()> {
    if let Some(b) = host_budget().filter(|&b| bytes > b) {
        let whose = if HOST_BUDGET.load(std::sync::atomic::Ordering::Relaxed) == u64::MAX {
            " (the default: three quarters of physical memory)"
        } else {
            ""
        };
        return Err(Error::TooLarge(format!(
            "{what} may need {} MiB of host memory, past the host budget of {} MiB{whose}",
            bytes >> 20,
            b >> 20
        )));
    }
    match meminfo("MemAvailable:") {
        Some(a) if bytes > a => Err(Error::TooLarge(format!(
            "{what} may need {} MiB of host memory; {} MiB are available",
            bytes >> 20,
            a >> 20
        ))),
        _ => Ok(()),
    }
}
