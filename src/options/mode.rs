//! What a frame shows of each pixel's ray: compositing or an order-independent projection.
use crate::error::{Error, Result};

/// What a frame shows of the splats along each pixel's ray (`RenderOptions::mode`).
///
/// The projection modes are order-independent: they draw no visibility order and blend by
/// maximum or sum (`--mode mip|minip|average|xray`). Each splat carries its value (a classified
/// volume's density, normalised to the transfer function's range; a splat set made by
/// `SplatSet::from_fn`, its opacity), weighed by its footprint.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Mode {
    /// Emission and absorption composited in visibility order (the default).
    #[default]
    Composite,
    /// Maximum intensity projection: per pixel the largest footprint-weighted value (a footprint
    /// weighs 1 at its centre) over the largest weight, mapped through the colour map, at
    /// opacity that largest weight (the footprints' coverage).
    Mip,
    /// Minimum intensity projection over the extracted voxels: the smallest value, as `Mip` of
    /// one minus the value.
    Minip,
    /// The mean value along the ray, weighed by the footprints' integrals, mapped through the
    /// colour map.
    Average,
    /// A digitally reconstructed radiograph: opacity 1 − exp(−Σ τ), the extinction summed along
    /// the ray, in the colour map's top colour.
    Xray,
    /// The isosurface where the trilinear reconstruction of the values crosses
    /// `RenderOptions::iso`: one oriented disc per cell the value crosses (EWA surface splatting),
    /// headlight-shaded, the nearest surface per pixel blended over a thin depth band. The values
    /// are the volume's, normalised to [0, 1] (a bricked volume's whole range; a classified set's
    /// splat values, `Splat::ijk[3]`); its colour is the colour map's at the iso value (default:
    /// bone). Drawn by the compute tile compositor.
    Iso,
}

impl Mode {
    /// Every mode, for help texts and tests.
    pub const ALL: [Mode; 6] = [Mode::Composite, Mode::Mip, Mode::Minip, Mode::Average, Mode::Xray, Mode::Iso];

    /// The name the CLI takes.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Composite => "composite",
            Mode::Mip => "mip",
            Mode::Minip => "minip",
            Mode::Average => "average",
            Mode::Xray => "xray",
            Mode::Iso => "iso",
        }
    }

    /// Whether the mode draws no visibility order (not `Composite`): the projections and the
    /// isosurface.
    pub fn is_projection(self) -> bool {
        self != Mode::Composite
    }

    /// The code `Frame::rect[2]` carries (`PROJECT_*` in glsl/shared/types.glsl).
    pub fn code(self) -> u32 {
        match self {
            Mode::Composite => 0,
            Mode::Mip => 1,
            Mode::Minip => 2,
            Mode::Average => 3,
            Mode::Xray => 4,
            Mode::Iso => 5,
        }
    }

    /// How its footprints blend: by maximum (`Mip`, `Minip`) or by sum.
    pub fn takes_max(self) -> bool {
        matches!(self, Mode::Mip | Mode::Minip)
    }
}

impl std::fmt::Display for Mode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Mode {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        Mode::ALL.into_iter().find(|m| m.name() == s).ok_or_else(|| {
            Error::InvalidArgument(format!("unknown mode '{s}' (composite, mip, minip, average, xray, iso)"))
        })
    }
}
