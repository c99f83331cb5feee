//! Isosurfaces' host side (`Mode::Iso`): the scene's values as a dense 16-bit field
//! ([`IsoField`]), made once per scene and uploaded once, from which the device extracts each
//! frame's surface splats (`iso_count`, `iso_scan`, `iso_cells`, `iso_splats`): so a new iso value
//! costs a push constant, not an upload.
pub use crate::constants::ISO_SEGMENT;
use crate::error::{check_host_memory, Error, Result};
use std::sync::atomic::{AtomicU64, Ordering};

/// The quantisation of the field's values (a bricked store's own).
pub const ISO_Q: f32 = 65535.0;

/// The scene's values, quantised to 16 bits, on the dense grid.
#[derive(Clone, Debug)]
pub struct IsoField {
    /// Voxels along x, y, z.
    pub dims: [u32; 3],
    /// Two values a word: voxel v (x fastest) in word v / 2, the low half when v is even.
    pub words: Vec<u32>,
    /// Per voxel row (j + ny k), per segment of `ISO_SEGMENT` voxels along x, its largest value:
    /// the cells of a block whose voxels all lie below the iso value are skipped whole.
    pub rows: Vec<u32>,
    /// Tells one field from another (`Engine::tag`: uploaded once).
    pub id: u64,
}

static NEXT_ID: AtomicU64 = AtomicU64::new(1);

impl IsoField {
    /// The field of a scene: a bricked store's stored values (its quantisation, exactly), or a
    /// splat set's values (`Splat::ijk[3]`, 0 where no splat lies).
    pub fn of(set: &crate::volume::SplatSet, bricks: Option<&crate::bricks::BrickScene>) -> Result<Self> {
        let dims = set.grid().dims;
        let n = dims.iter().map(|&d| d as u64).product::<u64>();
        let bytes = n.div_ceil(2) * 4 + n * 2;
        check_host_memory(bytes, &format!("the isosurface's field of {} x {} x {} voxels", dims[0], dims[1], dims[2]))?;
        if n > u32::MAX as u64 {
            return Err(Error::TooLarge(format!("an isosurface over {n} voxels (at most {})", u32::MAX)));
        }
        let mut q = vec![0u16; n as usize];
        let (nx, ny) = (dims[0] as usize, dims[1] as usize);
        match bricks {
            Some(scene) => {
                let s = &scene.store;
                for hd in &s.headers {
                    let base = hd.coords().map(|c| (c * crate::bricks::BRICK) as usize);
                    for rec in s.brick_records(hd).iter() {
                        let l = crate::bricks::local_cell(rec & 511).map(|c| c as usize);
                        let (x, y, z) = (base[0] + l[0], base[1] + l[1], base[2] + l[2]);
                        q[x + nx * (y + ny * z)] = (rec >> 16) as u16;
                    }
                }
            }
            None => {
                for sp in set.splats() {
                    let v = f32::from_bits(sp.ijk[3]);
                    let i = sp.ijk[0] as usize + nx * (sp.ijk[1] as usize + ny * sp.ijk[2] as usize);
                    q[i] = quantise(v);
                }
            }
        }
        let rows: Vec<u32> = q
            .chunks(nx.max(1))
            .flat_map(|row| row.chunks(ISO_SEGMENT as usize).map(|s| s.iter().copied().max().unwrap_or(0) as u32))
            .collect();
        let words = q.chunks(2).map(|p| p[0] as u32 | (*p.get(1).unwrap_or(&0) as u32) << 16).collect();
        Ok(Self { dims, words, rows, id: NEXT_ID.fetch_add(1, Ordering::Relaxed) })
    }

    /// The quantised value at voxel (i, j, k); 0 outside the grid (as the ray caster's field).
    pub fn at(&self, i: i64, j: i64, k: i64) -> u32 {
        let [nx, ny, nz] = self.dims.map(|d| d as i64);
        if i < 0 || j < 0 || k < 0 || i >= nx || j >= ny || k >= nz {
            return 0;
        }
        self.value((i + nx * (j + ny * k)) as usize)
    }

    /// The quantised value of voxel `v` (x fastest).
    fn value(&self, v: usize) -> u32 {
        (self.words[v / 2] >> (16 * (v % 2))) & 0xffff
    }

    /// The ray caster's field of it: (value, 1, 0, 0) per voxel (`plan::FieldKind::Iso`).
    pub fn dense(&self) -> crate::volume::DenseField {
        let n = self.dims.iter().map(|&d| d as usize).product::<usize>();
        let values = (0..n).map(|v| [self.value(v) as f32 / ISO_Q, 1.0, 0.0, 0.0]).collect();
        crate::volume::DenseField { dims: self.dims, values }
    }

    /// Device bytes: the values and the row ranges.
    pub fn bytes(&self) -> u64 {
        (self.words.len() + self.rows.len()) as u64 * 4
    }
}

/// A normalised value as the field stores it.
pub fn quantise(v: f32) -> u16 {
    (v.clamp(0.0, 1.0) * ISO_Q).round() as u16
}

/// The least quantised value at or above `iso` (`IsoPush::threshold`): 65536 above 1, where no
/// voxel is inside.
pub fn threshold(iso: f32) -> u32 {
    if iso > 1.0 {
        return 1 << 16;
    }
    let mut t = (iso.max(0.0) * ISO_Q).ceil() as u32;
    while t > 0 && (t - 1) as f32 / ISO_Q >= iso {
        t -= 1;
    }
    while t <= 0xffff && (t as f32 / ISO_Q) < iso {
        t += 1;
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn threshold_is_the_least_value_inside() {
        for iso in [0.0f32, 1e-6, 0.3, 0.5, 0.73, 0.999_99, 1.0] {
            let t = threshold(iso);
            assert!(t as f32 / ISO_Q >= iso, "{iso}: {t}");
            assert!(t == 0 || ((t - 1) as f32 / ISO_Q) < iso, "{iso}: {t}");
        }
        assert_eq!(threshold(1.5), 1 << 16);
        assert_eq!(threshold(-0.5), 0);
    }
}
