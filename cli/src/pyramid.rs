//! Which part of an OME-Zarr --volume one frame needs: when its view sees only part of the image,
//! the box a store reads (`VolumeHints::crop`; the level is `open`'s choice).
use crate::open::{camera_of, Content, SceneArgs};
use voxsplat::{glam::Vec3, Error, Result};

/// With --eye and --target (a view that does not frame the image), the bounds of the part of the
/// image's box (level 0's, in the grid's centred frame) the view sees, when that is not all of it,
/// and the view: a store then reads only the chunks it may see there. `None` otherwise.
pub fn seen_box(a: &SceneArgs, path: &std::path::Path) -> Result<Option<([[f32; 3]; 2], voxsplat::Camera)>> {
    if a.eye.is_none() || a.target.is_none() {
        return Ok(None);
    }
    let image = voxsplat::loaders::OmeZarr::open(path)?;
    let l = &image.levels[0];
    let grid = voxsplat::Grid::centered(l.dims, l.spacing)?;
    let camera = camera_of(a, &grid, &Content { orientation: None, bounds: None })?;
    let half = Vec3::from(l.dims.map(|d| d as f32)) * Vec3::from(l.spacing) * 0.5;
    let seen = camera.box_in_view(-half, half, voxsplat::loaders::VIEW_MARGIN_PX).ok_or_else(|| {
        Error::InvalidArgument(format!("{}: the view (--eye, --target) sees none of the image", path.display()))
    })?;
    let whole = (seen[0] + half).max_element() <= 0.0 && (half - seen[1]).max_element() <= 0.0;
    if whole {
        return Ok(None);
    }
    eprintln!(
        "OME-Zarr: the view sees within [{:.1}, {:.1}, {:.1}] to [{:.1}, {:.1}, {:.1}] of the image: only the chunks in view are read, \
         its values normalised by their own range (a transfer function's range keeps colours from view to view)",
        seen[0].x, seen[0].y, seen[0].z, seen[1].x, seen[1].y, seen[1].z
    );
    Ok(Some(([seen[0].to_array(), seen[1].to_array()], camera)))
}
