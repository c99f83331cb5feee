//! How coarse a drag frame draws to hold `--drag-ms`, and the frame times `view` prints at exit.

/// A drag frame's most coarseness (`State::coarse`): a quarter of the render scale (its floor)
/// and eight times the levels of detail's pixel bound.
pub const DRAG_COARSE_MAX: f32 = 8.0;

/// The next drag frame's coarseness after a window frame of `ms` at `coarse`. A frame's cost
/// goes with its pixels, the square of the scale, so the step is the square root of the miss;
/// within 0.7 to 1 of the target it holds (the levels of detail come in steps, and chasing the
/// target closer only flips between two).
///
/// The first drag starts from the still frame (`coarse` 1): a drag frame right after release
/// of the button is as coarse as the last full frame's time says it must be, not a guess.
pub fn next_coarse(coarse: f32, ms: f64, target_ms: f64) -> f32 {
    let ratio = (ms / target_ms).sqrt() as f32;
    if !ratio.is_finite() || (0.7..=1.0).contains(&ratio) {
        return coarse;
    }
    (coarse * ratio).clamp(1.0, DRAG_COARSE_MAX)
}

/// One frame drawn: milliseconds drawing the volume, the render scale when a drag drew it, and
/// milliseconds for the whole window frame (the panel, the volume, the overlay, the present).
pub type FrameTime = (f64, Option<f32>, f64);

/// The lines `view` prints at exit: the still frames' and the drag frames' medians. The first
/// frame is left out of the still ones: it builds what the others reuse (the levels of detail,
/// the uploads), and the first line before these gives its time from the start.
pub fn summary(times: &[FrameTime], drag_ms: f64) -> Vec<String> {
    let mut lines = Vec::new();
    let later = times.get(1..).unwrap_or_default();
    for (what, dragged) in [("still frames after the first", false), ("drag frames", true)] {
        let t: Vec<_> = later.iter().filter(|t| t.1.is_some() == dragged).collect();
        if t.is_empty() {
            continue;
        }
        let volume = median(t.iter().map(|t| t.0).collect());
        let window = median(t.iter().map(|t| t.2).collect());
        let scale = median(t.iter().map(|t| t.1.unwrap_or(1.0) as f64).collect());
        let mut line = format!(
            "{} {what}: median {volume:.1} ms the volume, {window:.1} ms the window frame, scale {scale:.2}",
            t.len()
        );
        if dragged {
            let over = t.iter().filter(|t| t.2 > drag_ms).count();
            line += &format!(" ({over} over --drag-ms {drag_ms})");
        }
        lines.push(line);
    }
    lines
}

/// The middle value; of an even count, the mean of the two middle ones.
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame over the target steps coarser by the square root of the miss, one under 0.7 of
    /// it finer, one within holds; the bounds hold; the first drag starts from the still frame.
    #[test]
    fn coarseness_follows_the_target() {
        assert_eq!(next_coarse(2.0, 400.0, 100.0), 4.0);
        assert_eq!(next_coarse(2.0, 25.0, 100.0), 1.0);
        assert_eq!(next_coarse(2.0, 64.0, 100.0), 2.0);
        assert_eq!(next_coarse(4.0, 1e6, 100.0), DRAG_COARSE_MAX);
        assert_eq!(next_coarse(1.0, 1.0, 100.0), 1.0);
        // A 900 ms still frame: the first drag frame draws at a third of the scale.
        assert_eq!(next_coarse(1.0, 900.0, 100.0), 3.0);
        assert_eq!(next_coarse(3.0, f64::NAN, 100.0), 3.0);
    }

    /// The first frame counts in neither median; an even count takes the middle two's mean; the
    /// drag line counts the frames over the target.
    #[test]
    fn summary_leaves_out_the_first_frame() {
        let times = [
            (1900.0, None, 1950.0),
            (170.0, Some(0.5), 190.0),
            (70.0, Some(0.4), 80.0),
            (880.0, None, 900.0),
            (60.0, Some(0.4), 70.0),
            (920.0, None, 940.0),
        ];
        let lines = summary(&times, 100.0);
        assert_eq!(lines.len(), 2);
        assert!(lines[0].starts_with("2 still frames after the first: median 900.0 ms the volume, 920.0 ms"));
        assert!(lines[1].starts_with("3 drag frames: median 70.0 ms the volume, 80.0 ms"));
        assert!(lines[1].ends_with("(1 over --drag-ms 100)"), "{}", lines[1]);
        assert!(summary(&times[..1], 100.0).is_empty());
        assert!(summary(&[], 100.0).is_empty());
    }
}
