//! Classification (section 1.2.5): a transfer function t = F(∇, ρ) maps each voxel's density (and
//! optionally its gradient magnitude) to colour and opacity; voxels with zero opacity are not
//! extracted. Optional Phong shading with a headlight is applied to the voxels before splatting,
//! as in the seed (docs/MODEL.md).
//!
//! ```
//! use voxsplat::{classify::{classify, TransferFunction}, loaders::ScalarVolume};
//! // Scalars through a preset transfer function: one splat per voxel it does not make transparent.
//! let values = (0..8 * 8 * 8).map(|i| i as f32 / 511.0).collect();
//! let volume = ScalarVolume { dims: [8; 3], spacing: [1.0; 3], values };
//! let set = classify(&volume, &TransferFunction::preset("ct")?, None)?;
//! assert!(set.len() <= 512);
//! # Ok::<(), voxsplat::Error>(())
//! ```
use crate::error::{Error, Result};
use crate::volume::ScalarVolume;
use crate::volume::{Grid, SplatSet};
use glam::Vec3;
use serde::{Deserialize, Serialize};

/// Piecewise-linear colour and opacity over density normalised to [0, 1].
///
/// ```
/// use voxsplat::classify::TransferFunction;
/// let ct = TransferFunction::preset("ct")?;
/// // Or points of (value in [0, 1], straight RGBA), as `voxsplat render --tf FILE` reads them.
/// let own = TransferFunction::from_toml("points = [[0.2, [1, 0.5, 0, 0]], [0.8, [1, 1, 1, 0.6]]]")?;
/// assert!(own.eval(0.8)[3] > ct.eval(0.0)[3]);
/// # Ok::<(), voxsplat::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TransferFunction {
    /// (density in [0, 1], [r, g, b, opacity]) control points, in increasing density.
    #[serde(deserialize_with = "strict::points")]
    pub points: Vec<(f32, [f32; 4])>,
    /// Opacity × (|∇ρ| / max |∇ρ|)^gradient_weight; 0 disables the weighting.
    #[serde(default)]
    pub gradient_weight: f32,
    /// Densities mapped to 0 and 1 (default: the data's minimum and maximum).
    #[serde(default, deserialize_with = "strict::range")]
    pub range: Option<(f32, f32)>,
    /// Extraction threshold: voxels whose normalised density is below it are never extracted.
    #[serde(default)]
    pub threshold: f32,
}

/// Deserializers that refuse what a loose tuple would drop: a colour of more or fewer than four
/// components, a point or a range with a third element.
mod strict {
    use serde::de::{self, Deserializer, IgnoredAny, SeqAccess, Visitor};
    use std::fmt;

    /// `[a, b]` of exactly two elements.
    fn pair<'de, D: Deserializer<'de>, A: de::Deserialize<'de>, B: de::Deserialize<'de>>(
        d: D,
        what: &'static str,
    ) -> Result<(A, B), D::Error> {
        struct Pair<A, B>(&'static str, std::marker::PhantomData<(A, B)>);
        impl<'de, A: de::Deserialize<'de>, B: de::Deserialize<'de>> Visitor<'de> for Pair<A, B> {
            type Value = (A, B);
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str(self.0)
            }
            fn visit_seq<S: SeqAccess<'de>>(self, mut s: S) -> Result<(A, B), S::Error> {
                let a = s.next_element()?.ok_or_else(|| de::Error::invalid_length(0, &self))?;
                let b = s.next_element()?.ok_or_else(|| de::Error::invalid_length(1, &self))?;
                if s.next_element::<IgnoredAny>()?.is_some() {
                    return Err(de::Error::invalid_length(3, &self));
                }
                Ok((a, b))
            }
        }
        d.deserialize_seq(Pair(what, std::marker::PhantomData))
    }

    struct Point((f32, [f32; 4]));
    impl<'de> de::Deserialize<'de> for Point {
        fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
            let (density, c): (f32, Vec<f32>) = pair(d, "a point [density, [r, g, b, opacity]]")?;
            let c: [f32; 4] = c.try_into().map_err(|c: Vec<f32>| {
                de::Error::invalid_length(c.len(), &"a colour of 4 components [r, g, b, opacity]")
            })?;
            Ok(Point((density, c)))
        }
    }

    pub fn points<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<(f32, [f32; 4])>, D::Error> {
        let points: Vec<Point> = de::Deserialize::deserialize(d)?;
        Ok(points.into_iter().map(|p| p.0).collect())
    }

    struct Range((f32, f32));
    impl<'de> de::Deserialize<'de> for Range {
        fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
            pair(d, "a range [low, high]").map(Range)
        }
    }

    pub fn range<'de, D: Deserializer<'de>>(d: D) -> Result<Option<(f32, f32)>, D::Error> {
        let r: Option<Range> = de::Deserialize::deserialize(d)?;
        Ok(r.map(|r| r.0))
    }
}

/// Named transfer functions: (name, description).
pub const TF_PRESETS: &[(&str, &str)] = &[
    ("ramp", "grey ramp, opacity rising from a tenth of the range"),
    ("ct", "CT: soft tissue faint red, contrast and bone opaque white"),
    ("bonsai", "the bonsai CT: twigs green, trunk and pot brown, the base plate transparent"),
    ("mri", "T1-weighted MRI head: scalp a faint skin tone, grey matter rose, white matter opaque ivory"),
];

/// Presets drawn with headlight shading by default: those where shading raised the luminance
/// contrast over the object by at least a fifth on the gallery's views (bonsai +45 %; ct on the
/// stent +4 %, ramp on heptane +5 %: left unshaded; docs/RESULTS.md).
pub const SHADED_PRESETS: &[&str] = &["bonsai"];

impl TransferFunction {
    /// A named preset: `ramp`, `ct`, `bonsai`, `mri` (docs/guide/cli.md).
    pub fn preset(name: &str) -> Result<Self> {
        let p = |points: Vec<(f32, [f32; 4])>| Self { points, gradient_weight: 0.0, range: None, threshold: 0.0 };
        match name {
            "ramp" => Ok(p(vec![(0.1, [0.0, 0.0, 0.0, 0.0]), (1.0, [1.0, 1.0, 1.0, 0.6])])),
            "ct" => Ok(p(vec![
                (0.0, [0.0, 0.0, 0.0, 0.0]),
                (0.12, [0.0, 0.0, 0.0, 0.0]),
                (0.2, [0.8, 0.3, 0.2, 0.03]),
                (0.45, [1.0, 0.9, 0.8, 0.6]),
                (1.0, [1.0, 1.0, 1.0, 0.95]),
            ])),
            // The base plate the bonsai stands on (0.13-0.19) is left transparent; twigs (0.25-0.31)
            // green; trunk, soil and pot brown (tuned beside VTK: docs/log/2026-11-24-orientation-framing-presets-gallery.md).
            "bonsai" => Ok(p(vec![
                (0.0, [0.0, 0.0, 0.0, 0.0]),
                (0.22, [0.0, 0.0, 0.0, 0.0]),
                (0.25, [0.22, 0.6, 0.12, 0.35]),
                (0.31, [0.25, 0.6, 0.15, 0.35]),
                (0.36, [0.55, 0.33, 0.14, 0.9]),
                (1.0, [0.65, 0.42, 0.25, 0.95]),
            ])),
            // T1 over the data's range: fluid and bone (below 0.25) transparent, scalp (~0.4) faint,
            // grey matter (~0.6) translucent, white matter (~0.95) near opaque (issue 29, tuned on
            // `make-volume --phantom` beside VTK: docs/log/2026-11-24-orientation-framing-presets-gallery.md).
            "mri" => Ok(p(vec![
                (0.0, [0.0, 0.0, 0.0, 0.0]),
                (0.3, [0.0, 0.0, 0.0, 0.0]),
                (0.4, [0.85, 0.62, 0.5, 0.015]),
                (0.5, [0.85, 0.62, 0.5, 0.015]),
                (0.6, [0.8, 0.5, 0.5, 0.12]),
                (0.85, [0.95, 0.9, 0.82, 0.5]),
                (1.0, [1.0, 0.97, 0.9, 0.8]),
            ])),
            other => Err(Error::InvalidArgument(format!(
                "unknown transfer function '{other}' ({})",
                TF_PRESETS.iter().map(|t| t.0).collect::<Vec<_>>().join(", ")
            ))),
        }
    }

    /// Parse and check a TOML transfer function (`points = [[0.2, [1, 0, 0, 0.5]], ...]`).
    pub fn from_toml(text: &str) -> Result<Self> {
        let tf: Self = toml::from_str(text).map_err(|e| Error::InvalidArgument(format!("transfer function: {e}")))?;
        tf.validate()?;
        Ok(tf)
    }

    /// The TOML `from_toml` reads back (to save an edited transfer function).
    pub fn to_toml(&self) -> Result<String> {
        toml::to_string(self).map_err(|e| Error::InvalidArgument(format!("transfer function: {e}")))
    }

    /// Reject transfer functions no classification can use.
    pub fn validate(&self) -> Result<()> {
        let bad = |m: &str| Err(Error::InvalidArgument(format!("transfer function: {m}")));
        if self.points.is_empty() || self.points.len() > 4096 {
            return bad("needs 1 to 4096 points");
        }
        for w in self.points.windows(2) {
            if w[1].0.partial_cmp(&w[0].0).is_none_or(|o| o == std::cmp::Ordering::Less) {
                return bad("densities must increase");
            }
        }
        for (d, c) in &self.points {
            if !d.is_finite() || c.iter().any(|v| !v.is_finite() || *v < 0.0) || c[3] > 1.0 {
                return bad("values must be finite, non-negative, opacity at most 1");
            }
        }
        if !self.threshold.is_finite() {
            return bad("threshold must be finite");
        }
        if !(self.gradient_weight.is_finite() && self.gradient_weight >= 0.0) {
            return bad("gradient_weight must be non-negative");
        }
        if let Some((a, b)) = self.range {
            if !(a.is_finite() && b.is_finite() && b > a) {
                return bad("range must be finite and increasing");
            }
        }
        Ok(())
    }

    /// Straight RGBA at normalised value `d`, linear between the points.
    pub fn eval(&self, d: f32) -> [f32; 4] {
        let pts = &self.points;
        if d <= pts[0].0 {
            return pts[0].1;
        }
        for w in pts.windows(2) {
            if d <= w[1].0 {
                let s = if w[1].0 > w[0].0 { (d - w[0].0) / (w[1].0 - w[0].0) } else { 1.0 };
                return [0, 1, 2, 3].map(|c| w[0].1[c] + (w[1].1[c] - w[0].1[c]) * s);
            }
        }
        pts[pts.len() - 1].1
    }
}

/// Phong shading with a headlight, applied per voxel before splatting.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shading {
    /// Direction the light travels (the view direction, for a headlight), in grid coordinates.
    pub light: Vec3,
    /// Ambient term.
    pub ambient: f32,
    /// Diffuse (Lambert) weight.
    pub diffuse: f32,
    /// Specular (Phong) weight.
    pub specular: f32,
    /// Phong exponent.
    pub shininess: f32,
}

impl Shading {
    /// Headlight shading: the light at the eye, looking along `view_dir`.
    pub fn headlight(view_dir: Vec3) -> Self {
        Self { light: view_dir.normalize_or_zero(), ambient: 0.3, diffuse: 0.7, specular: 0.25, shininess: 20.0 }
    }
}

/// Classify a loaded volume into splats. Gradients by central differences on the grid.
pub fn classify(vol: &ScalarVolume, tf: &TransferFunction, shading: Option<Shading>) -> Result<SplatSet> {
    classify_on(Grid::centered(vol.dims, vol.spacing)?, vol, tf, shading)
}

/// Classify `vol` on `grid` (its dimensions; a placed or sheared grid, `Orientation::grid`).
pub fn classify_on(
    grid: Grid,
    vol: &ScalarVolume,
    tf: &TransferFunction,
    shading: Option<Shading>,
) -> Result<SplatSet> {
    let voxel = voxel_classifier(grid, vol, tf, shading)?;
    SplatSet::from_fn_valued(grid, voxel)
}

/// Several scalar volumes on one grid (the channels of a fluorescence image), each classified by
/// its own transfer function, combined per voxel into one splat: emission and extinction added
/// (optical depths summed, colours weighed by them), the value the largest of the channels'.
/// Refused: no channel, more than `MAX_CHANNELS`, or channels whose dimensions differ.
pub fn classify_channels(
    grid: Grid,
    channels: &[(&ScalarVolume, &TransferFunction)],
    shading: Option<Shading>,
) -> Result<SplatSet> {
    if channels.is_empty() || channels.len() > MAX_CHANNELS {
        return Err(Error::InvalidArgument(format!(
            "{} channels: a frame combines 1 to {MAX_CHANNELS}",
            channels.len()
        )));
    }
    for (i, (v, _)) in channels.iter().enumerate() {
        if v.dims != grid.dims {
            return Err(Error::InvalidArgument(format!(
                "channel {} is {:?} voxels, the grid {:?}: channels share one grid",
                i + 1,
                v.dims,
                grid.dims
            )));
        }
    }
    let voxels: Vec<_> =
        channels.iter().map(|(v, tf)| voxel_classifier(grid, v, tf, shading)).collect::<Result<_>>()?;
    SplatSet::from_fn_valued(grid, |i, j, k| combine(voxels.iter().map(|f| f(i, j, k))))
}

/// A voxel classified: its straight colour and opacity and its normalised value, or `None` where
/// nothing is drawn.
pub type Classified = Option<([f32; 4], f32)>;

/// Most channels `classify_channels` combines.
pub const MAX_CHANNELS: usize = 4;

/// Voxels that share a place, combined: emission and extinction added (optical depths summed,
/// straight colours weighed by them), the value the largest; `None` where none is drawn.
pub fn combine(voxels: impl Iterator<Item = Classified>) -> Classified {
    let (mut rgb_tau, mut tau, mut value, mut any) = ([0.0f64; 3], 0.0f64, 0.0f32, false);
    for (c, v) in voxels.flatten() {
        let t = crate::volume::optical_depth(c[3]) as f64;
        for ch in 0..3 {
            rgb_tau[ch] += c[ch] as f64 * t;
        }
        tau += t;
        value = value.max(v);
        any = true;
    }
    if !any || tau <= 0.0 {
        return None;
    }
    let rgb = rgb_tau.map(|c| (c / tau) as f32);
    Some(([rgb[0], rgb[1], rgb[2], (1.0 - (-tau).exp()) as f32], value))
}

/// The classification of `vol` on `grid` as a function of the voxel: its colour and normalised
/// value where the transfer function draws it.
fn voxel_classifier<'a>(
    grid: Grid,
    vol: &'a ScalarVolume,
    tf: &'a TransferFunction,
    shading: Option<Shading>,
) -> Result<impl Fn(u32, u32, u32) -> Classified + 'a> {
    if grid.dims != vol.dims {
        return Err(Error::InvalidArgument(format!("a {:?} grid for a {:?} volume", grid.dims, vol.dims)));
    }
    let [nx, ny, nz] = vol.dims;
    let (lo, hi) = tf.range.unwrap_or_else(|| crate::volume::value_span(&vol.values));
    // In f64: the span of an f32 range may pass f32's largest value.
    let span = if hi > lo { hi as f64 - lo as f64 } else { 1.0 };
    let at = move |i: i64, j: i64, k: i64| -> f32 {
        let (i, j, k) = (i.clamp(0, nx as i64 - 1), j.clamp(0, ny as i64 - 1), k.clamp(0, nz as i64 - 1));
        let v = vol.values[(i + nx as i64 * (j + ny as i64 * k)) as usize];
        if v.is_finite() {
            ((v as f64 - lo as f64) / span) as f32
        } else {
            0.0
        }
    };
    field_classifier(grid, tf, shading, at)
}

/// Classify the normalised field `at` (indices clamped to the grid by `at` itself) on `grid`:
/// the dense volume's classification (`classify`) and the bricked store's (`bricks`) share it.
pub fn classify_field(
    grid: Grid,
    tf: &TransferFunction,
    shading: Option<Shading>,
    at: impl Fn(i64, i64, i64) -> f32,
) -> Result<SplatSet> {
    SplatSet::from_fn_valued(grid, field_classifier(grid, tf, shading, at)?)
}

/// `classify_field`'s per-voxel function.
fn field_classifier<'a>(
    grid: Grid,
    tf: &'a TransferFunction,
    shading: Option<Shading>,
    at: impl Fn(i64, i64, i64) -> f32 + 'a,
) -> Result<impl Fn(u32, u32, u32) -> Classified + 'a> {
    tf.validate()?;
    let [nx, ny, nz] = grid.dims;
    let at = std::rc::Rc::new(at);
    let field = at.clone();
    let grad = move |i: u32, j: u32, k: u32| -> Vec3 {
        let (i, j, k) = (i as i64, j as i64, k as i64);
        let at = &field;
        Vec3::from(grid.gradient([
            at(i + 1, j, k) - at(i - 1, j, k),
            at(i, j + 1, k) - at(i, j - 1, k),
            at(i, j, k + 1) - at(i, j, k - 1),
        ]))
    };
    let gmax = if tf.gradient_weight > 0.0 || shading.is_some() {
        let mut m = 0.0f32;
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    m = m.max(grad(i, j, k).length());
                }
            }
        }
        m.max(1e-12)
    } else {
        1.0
    };
    Ok(move |i: u32, j: u32, k: u32| {
        let d = at(i as i64, j as i64, k as i64);
        if d < tf.threshold {
            return None;
        }
        let mut c = tf.eval(d);
        if c[3] <= 0.0 {
            return None;
        }
        if tf.gradient_weight > 0.0 || shading.is_some() {
            let g = grad(i, j, k);
            if tf.gradient_weight > 0.0 {
                c[3] *= (g.length() / gmax).powf(tf.gradient_weight);
            }
            if let Some(s) = shading {
                let n = g.normalize_or_zero();
                let ndl = n.dot(-s.light).abs();
                let lit = s.ambient + s.diffuse * ndl;
                let spec = s.specular * ndl.powf(s.shininess);
                for ch in c.iter_mut().take(3) {
                    *ch = (*ch * lit + spec).min(1.0);
                }
            }
        }
        (c[3] > 0.0).then_some((c, d.clamp(0.0, 1.0)))
    })
}

#[cfg(test)]
mod toml_tests {
    use super::TransferFunction;

    #[test]
    fn a_transfer_function_survives_toml() {
        let mut tf = TransferFunction::preset("ct").unwrap();
        assert_eq!(TransferFunction::from_toml(&tf.to_toml().unwrap()).unwrap(), tf);
        tf.range = Some((20.0, 300.5));
        tf.gradient_weight = 0.5;
        assert_eq!(TransferFunction::from_toml(&tf.to_toml().unwrap()).unwrap(), tf);
    }
}
