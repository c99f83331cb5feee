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

/// Most planes and sizes a series with localizers holds (more is a mixed folder).
const MAX_PLANES: usize = 8;

/// The images that share the plane and size of most of them, and a note for each left out; `None`
/// when no plane and size holds a strict majority of at least two (a mixed series, refused by
/// the caller as before). `name` names an image in notes.
pub(super) fn localizers(images: Vec<Image>, name: &dyn Fn(&Image) -> String) -> Option<(Vec<Image>, Vec<String>)> {
    let same = |a: &Image, b: &Image| {
        a.size == b.size && (a.row - b.row).length() <= 1e-4 && (a.column - b.column).length() <= 1e-4
    };
    // Each plane and size once, with its count: a series of more than a few is mixed, not a
    // series with its localizers (and counting stays linear in the images).
    let mut groups: Vec<(&Image, usize)> = Vec::new();
    for i in &images {
        match groups.iter().position(|(g, _)| same(g, i)) {
            Some(k) => groups[k].1 += 1,
            None if groups.len() < MAX_PLANES => groups.push((i, 1)),
            None => return None,
        }
    }
    let (most, kept) = groups.iter().max_by_key(|(_, n)| *n).map(|(g, n)| ((*g).clone(), *n))?;
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
    images: Vec<Image>,
    normal: DVec3,
    name: &dyn Fn(&Image) -> String,
) -> (Vec<Image>, Vec<String>) {
    let step = |k: usize| (images[k + 1].position - images[k].position).dot(normal).abs();
    // The median of the whole series' gaps, once: a far slice or two barely moves it.
    let mut sorted: Vec<f64> = (0..images.len().saturating_sub(1)).map(step).collect();
    sorted.sort_by(f64::total_cmp);
    let median = sorted.get(sorted.len().saturating_sub(1) / 2).copied().unwrap_or(0.0);
    let far = |gap: f64| median > 0.0 && gap > FAR_GAPS * median;
    // Kept: images[lo..hi].
    let (mut lo, mut hi) = (0, images.len());
    let mut notes = Vec::new();
    while hi - lo > 3 {
        let (first, last) = (step(lo), step(hi - 2));
        let (at, gap) = match (far(first), far(last)) {
            (false, false) => break,
            (true, false) => (lo, first),
            (false, true) => (hi - 1, last),
            (true, true) if first >= last => (lo, first),
            (true, true) => (hi - 1, last),
        };
        if at == lo {
            lo += 1;
        } else {
            hi -= 1;
        }
        notes.push(format!(
            "left out {}: it lies {gap:.4} mm from the next slice, over {FAR_GAPS} times the median gap of \
             {median:.4} mm (a stray slice or a localizer)",
            name(&images[at])
        ));
    }
    (images.into_iter().skip(lo).take(hi - lo).collect(), notes)
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
