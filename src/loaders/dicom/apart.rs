//! Images a series leaves out, as a clinical viewer does: a localizer (a scout) filed in the series
//! with another plane or size, and a slice lying far from the rest (a gap more than `FAR_GAPS`
//! times the median). Drawn with the others, either would stretch the grid or its footprints until
//! the frame is empty.
use super::{bad, Image};
use crate::error::Result;
use glam::DVec3;

/// A slice at either end whose gap to its neighbour is more than this many times the median gap
/// lies apart from the series.
pub const FAR_GAPS: f64 = 10.0;

/// The images that share the plane and size of most of them, and a note for each left out; `None`
/// when no plane and size holds a strict majority of at least two (a mixed series, refused by
/// the caller as before). `name` names an image in notes.
pub(super) fn localizers(images: Vec<Image>, name: &dyn Fn(&Image) -> String) -> Option<(Vec<Image>, Vec<String>)> {
    let same = |a: &Image, b: &Image| {
        a.size == b.size && (a.row - b.row).length() <= 1e-4 && (a.column - b.column).length() <= 1e-4
    };
    let count = |i: &Image| images.iter().filter(|j| same(i, j)).count();
    let most = images.iter().max_by_key(|i| count(i))?.clone();
    let kept = count(&most);
    if kept == images.len() {
        return Some((images, Vec::new()));
    }
    if kept < 2 || 2 * kept <= images.len() {
        return None;
    }
    let notes = images
        .iter()
        .filter(|i| !same(i, &most))
        .map(|i| {
            format!(
                "left out {}: a localizer ({:?} pixels in another plane or size than the series' {kept} images of \
                 {:?})",
                name(i),
                i.size,
                most.size
            )
        })
        .collect();
    Some((images.into_iter().filter(|i| same(i, &most)).collect(), notes))
}

/// `images`, sorted along `normal`, less the slices at either end that lie apart (a gap over
/// `FAR_GAPS` times the median), with a note for each. Three slices or more are kept.
pub(super) fn far_slices(
    mut images: Vec<Image>,
    normal: DVec3,
    name: &dyn Fn(&Image) -> String,
) -> (Vec<Image>, Vec<String>) {
    let mut notes = Vec::new();
    while images.len() > 3 {
        let steps: Vec<f64> = images.windows(2).map(|w| (w[1].position - w[0].position).dot(normal).abs()).collect();
        let mut sorted = steps.clone();
        sorted.sort_by(f64::total_cmp);
        let median = sorted[(sorted.len() - 1) / 2];
        let (first, last) = (steps[0], steps[steps.len() - 1]);
        let far = |gap: f64| median > 0.0 && gap > FAR_GAPS * median;
        let (at, gap) = match (far(first), far(last)) {
            (false, false) => break,
            (true, false) => (0, first),
            (false, true) => (images.len() - 1, last),
            (true, true) if first >= last => (0, first),
            (true, true) => (images.len() - 1, last),
        };
        let image = images.remove(at);
        notes.push(format!(
            "left out {}: it lies {gap:.4} mm from the next slice, over {FAR_GAPS} times the median gap of \
             {median:.4} mm (a stray slice or a localizer)",
            name(&image)
        ));
    }
    (images, notes)
}

/// Refuses `images` (those kept) unless they share one size, plane, rescale and pixel spacing.
pub(super) fn agree(images: &[Image], what: &str, name: &dyn Fn(&Image) -> String) -> Result<()> {
    let first = &images[0];
    for i in images {
        if i.size != first.size {
            return Err(bad(
                what,
                format!("mixed sizes: {} is {:?}, {} {:?}", name(i), i.size, name(first), first.size),
            ));
        }
        if (i.row - first.row).length() > 1e-4 || (i.column - first.column).length() > 1e-4 {
            return Err(bad(
                what,
                format!("mixed orientations (a localizer?): {} and {} lie in different planes", name(first), name(i)),
            ));
        }
        if i.rescale != first.rescale {
            return Err(bad(
                what,
                format!("mixed rescale: {} {:?}, {} {:?}", name(first), first.rescale, name(i), i.rescale),
            ));
        }
        if (i.spacing[0] - first.spacing[0]).abs() > 1e-6 || (i.spacing[1] - first.spacing[1]).abs() > 1e-6 {
            return Err(bad(what, format!("mixed pixel spacing: {} and {}", name(first), name(i))));
        }
    }
    Ok(())
}
