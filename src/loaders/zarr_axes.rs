//! An OME-Zarr image's spatial axes: the last three, in array order z, y, x, each scaled into one
//! unit. Axes named x, y and z in another order are refused (they were scaled as z, y, x), and
//! a length unit on each (`micrometer`, `nanometer`: OME-NGFF's UDUNITS-2 names) converts its
//! scale into the unit of x (they were ignored: a z in nanometres beside an x in micrometres drew
//! z a thousand times too long).
use super::bad;
use crate::error::Result;

/// The metres in one of OME-NGFF's length units.
fn metres(unit: &str) -> Option<f64> {
    let si = |p: &str| match p {
        "yocto" => Some(1e-24),
        "zepto" => Some(1e-21),
        "atto" => Some(1e-18),
        "femto" => Some(1e-15),
        "pico" => Some(1e-12),
        "nano" => Some(1e-9),
        "micro" => Some(1e-6),
        "milli" => Some(1e-3),
        "centi" => Some(1e-2),
        "deci" => Some(1e-1),
        "" => Some(1.0),
        "deca" => Some(1e1),
        "hecto" => Some(1e2),
        "kilo" => Some(1e3),
        "mega" => Some(1e6),
        "giga" => Some(1e9),
        "tera" => Some(1e12),
        "peta" => Some(1e15),
        "exa" => Some(1e18),
        "zetta" => Some(1e21),
        "yotta" => Some(1e24),
        _ => None,
    };
    match unit {
        "angstrom" => Some(1e-10),
        "inch" => Some(0.0254),
        "foot" => Some(0.3048),
        "yard" => Some(0.9144),
        "mile" => Some(1609.344),
        "parsec" => Some(3.0857e16),
        _ => unit.strip_suffix("meter").and_then(si),
    }
}

/// One axis as the metadata gives it: its name, its type and its unit.
pub(super) struct AxisText<'a> {
    pub name: &'a str,
    pub kind: &'a str,
    pub unit: Option<&'a str>,
}

/// Checks that `axes` end in three spatial ones, in order z, y, x where they are so named, and
/// gives the factor that takes each one's scale (array order) into the unit of x: 1 where no
/// unit is given.
pub(super) fn spatial(axes: &[AxisText<'_>], what: &str) -> Result<[f64; 3]> {
    let n = axes.len();
    let names = || axes.iter().map(|a| a.name).collect::<Vec<_>>();
    let space: Vec<usize> = (0..n).filter(|&i| axes[i].kind == "space").collect();
    if n < 3 || space != [n - 3, n - 2, n - 1] {
        return Err(bad(what, format!("axes {:?}: a volume has three spatial axes, last (z, y, x)", names())));
    }
    let last = &axes[n - 3..];
    let named: Vec<&str> = last.iter().map(|a| a.name).collect();
    let mut sorted = named.clone();
    sorted.sort_unstable();
    if sorted == ["x", "y", "z"] && named != ["z", "y", "x"] {
        return Err(bad(
            what,
            format!("spatial axes {named:?}: they are read in array order z, y, x (OME-NGFF's), not by name"),
        ));
    }
    let unit = |a: &AxisText<'_>| match a.unit {
        None => Ok(None),
        Some(u) => metres(u).map(Some).ok_or_else(|| {
            bad(
                what,
                format!("axis {} has unit {u:?}: a spatial axis takes a length (micrometer, nanometer, ...)", a.name),
            )
        }),
    };
    let of_x = unit(&last[2])?;
    let mut factors = [1.0; 3];
    for (f, a) in factors.iter_mut().zip(last) {
        if let (Some(m), Some(x)) = (unit(a)?, of_x) {
            *f = m / x;
        }
    }
    Ok(factors)
}
