//! The scene flags' value parsers (clap `value_parser`s): numbers, vectors, sizes, levels.
use glam::Vec3;

/// `N` comma-separated finite numbers.
pub fn parse_floats<const N: usize>(s: &str) -> std::result::Result<[f32; N], String> {
    let parts: Vec<&str> = s.split(',').collect();
    if parts.len() != N {
        return Err(format!("expected {N} comma-separated numbers, got '{s}'"));
    }
    let mut v = [0.0f32; N];
    for (o, p) in v.iter_mut().zip(parts) {
        *o = p.trim().parse::<f32>().map_err(|_| format!("'{p}' is not a number"))?;
        if !o.is_finite() {
            return Err(format!("'{p}' is not finite"));
        }
    }
    Ok(v)
}

pub fn parse_background(s: &str) -> std::result::Result<[f32; 4], String> {
    let [r, g, b, a] = match s.split(',').count() {
        3 => {
            let [r, g, b] = parse_floats::<3>(s)?;
            [r, g, b, 1.0]
        }
        _ => parse_floats::<4>(s)?,
    };
    if [r, g, b, a].iter().all(|c| (0.0..=1.0).contains(c)) {
        Ok([r, g, b, a])
    } else {
        Err(format!("'{s}': each channel must be in [0, 1]"))
    }
}

pub fn parse_vec3(s: &str) -> std::result::Result<Vec3, String> {
    parse_floats::<3>(s).map(Vec3::from)
}

pub fn parse_size(s: &str) -> std::result::Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("expected WxH, got '{s}'"))?;
    let w: u32 = w.trim().parse().map_err(|_| format!("bad width '{w}'"))?;
    let h: u32 = h.trim().parse().map_err(|_| format!("bad height '{h}'"))?;
    if w == 0 || h == 0 {
        return Err("image size must be at least 1x1".into());
    }
    Ok((w, h))
}

/// `--level`: a pyramid level's number or `auto`.
pub fn parse_level(s: &str) -> std::result::Result<String, String> {
    match s {
        "auto" => Ok(s.into()),
        n => n.parse::<u32>().map(|_| s.into()).map_err(|_| format!("'{s}' is neither a level number nor auto")),
    }
}

pub fn parse_dims(s: &str) -> std::result::Result<[u32; 3], String> {
    let v: Vec<&str> = s.split(',').collect();
    if v.len() != 3 {
        return Err(format!("expected X,Y,Z, got '{s}'"));
    }
    let mut d = [0u32; 3];
    for (o, p) in d.iter_mut().zip(v) {
        *o = p.trim().parse().map_err(|_| format!("'{p}' is not a dimension"))?;
        if *o == 0 {
            return Err("dimensions must be positive".into());
        }
    }
    Ok(d)
}

pub fn parse_finite(s: &str) -> std::result::Result<f32, String> {
    let v: f32 = s.parse().map_err(|_| format!("'{s}' is not a number"))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("'{s}' is not finite"))
    }
}
