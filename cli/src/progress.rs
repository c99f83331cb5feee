//! A bar on stderr while a volume file streams into its store (hidden when stderr is not a
//! terminal, as under a test or a pipe).
use voxsplat::loaders::Progress;

/// A bar for loading `path`, and the `VolumeHints::progress` that moves it; clear the bar when
/// the load is done.
pub fn load_bar(path: &std::path::Path) -> (indicatif::ProgressBar, Progress) {
    let bar = indicatif::ProgressBar::new(0).with_message(format!("reading {}", path.display()));
    bar.set_style(
        indicatif::ProgressStyle::with_template("{msg} {bar:30} {percent}% {elapsed}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let moved = bar.clone();
    let progress = Progress::new(move |read, of| {
        moved.set_length(of);
        moved.set_position(read);
    });
    (bar, progress)
}
