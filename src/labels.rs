//! Label volumes (segmentations): each voxel an integer label, coloured by a table of colour,
//! opacity and visibility per label. A voxel takes its own label's entry (the nearest label), so
//! no label is ever interpolated into another; a label volume is drawn alone or over a scalar
//! volume on the same grid, the two combined per voxel (`classify::combine`).
//!
//! ```
//! use voxsplat::labels::LabelTable;
//! // A segmentation's labels: each value's colour, opacity and whether it is drawn.
//! let mut table = LabelTable::from_toml("[[label]]\nvalue = 1\ncolor = [0.8, 0.3, 0.2]\nopacity = 1.0\n")?;
//! table.set_visible(1, false)?;
//! assert!(!table.get(1).unwrap().visible);
//! # Ok::<(), voxsplat::Error>(())
//! ```
use crate::classify::{combine, Shading, TransferFunction};
use crate::error::{Error, Result};
use crate::volume::{Grid, ScalarVolume, SplatSet};
use serde::{Deserialize, Serialize};

/// Largest label value a table or a volume may hold: labels are read as f32, exact to 2^24.
pub const MAX_LABEL: u32 = 1 << 24;

/// Most entries in a label table.
pub const MAX_LABELS: usize = 1 << 16;

/// One label's look.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Label {
    /// The label's value in the volume.
    pub value: u32,
    /// Straight RGB, each in [0, 1].
    pub color: [f32; 3],
    /// Opacity of one voxel-length, in [0, 1].
    pub opacity: f32,
    /// Drawn (true, the default) or hidden.
    #[serde(default = "visible")]
    pub visible: bool,
}

fn visible() -> bool {
    true
}

/// The colours of a label volume's labels (`voxsplat render --labels FILE --label-table TOML`).
/// Label 0 is the background: never drawn unless the table lists it. A voxel whose label the
/// table lacks is hidden and counted (`FrameStats::unlabelled`).
///
/// ```
/// use voxsplat::labels::LabelTable;
/// let table = LabelTable::from_toml(r#"
/// [[label]]
/// value = 1
/// color = [1.0, 0.2, 0.2]
/// opacity = 0.8
/// [[label]]
/// value = 2
/// color = [0.2, 0.4, 1.0]
/// opacity = 0.5
/// visible = false
/// "#)?;
/// assert!(table.get(2).is_some_and(|l| !l.visible));
/// # Ok::<(), voxsplat::Error>(())
/// ```
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LabelTable {
    /// The labels, each value once.
    #[serde(rename = "label", default)]
    pub labels: Vec<Label>,
}

impl LabelTable {
    /// Parse and check a TOML table (`[[label]]` entries of value, color, opacity, visible).
    pub fn from_toml(text: &str) -> Result<Self> {
        let t: Self = toml::from_str(text).map_err(|e| Error::InvalidArgument(format!("label table: {e}")))?;
        t.validate()?;
        Ok(t)
    }

    /// The TOML `from_toml` reads back.
    pub fn to_toml(&self) -> Result<String> {
        toml::to_string(self).map_err(|e| Error::InvalidArgument(format!("label table: {e}")))
    }

    /// Reject tables no volume can use: no label, too many, a value listed twice or past
    /// `MAX_LABEL`, a colour or opacity outside [0, 1].
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(Error::InvalidArgument(format!("label table: {m}")));
        if self.labels.is_empty() || self.labels.len() > MAX_LABELS {
            return bad(format!("{} labels: a table holds 1 to {MAX_LABELS}", self.labels.len()));
        }
        let mut seen = std::collections::HashSet::new();
        for l in &self.labels {
            if l.value > MAX_LABEL {
                return bad(format!("label {} is past {MAX_LABEL} (labels are exact in f32 up to there)", l.value));
            }
            if !seen.insert(l.value) {
                return bad(format!("label {} is listed twice", l.value));
            }
            if !l.color.iter().chain([&l.opacity]).all(|c| (0.0..=1.0).contains(c)) {
                return bad(format!("label {}: colour and opacity must lie in [0, 1]", l.value));
            }
        }
        Ok(())
    }

    /// The entry of label `value`.
    pub fn get(&self, value: u32) -> Option<&Label> {
        self.labels.iter().find(|l| l.value == value)
    }

    /// Show or hide label `value` (an error if the table lacks it).
    pub fn set_visible(&mut self, value: u32, visible: bool) -> Result<()> {
        match self.labels.iter_mut().find(|l| l.value == value) {
            Some(l) => {
                l.visible = visible;
                Ok(())
            }
            None => Err(Error::InvalidArgument(format!("label table: no label {value}"))),
        }
    }
}

/// A label volume classified: its splats and the voxels whose label the table lacks.
#[derive(Clone, Debug)]
pub struct Labelled {
    /// The splats (each value lane holds its opacity; over a scalar volume, the scalar's value).
    pub set: SplatSet,
    /// Voxels, background (0) aside, whose label the table lacks: hidden.
    pub unlabelled: u64,
    /// Up to eight of those labels, smallest first, for the message.
    pub missing: Vec<u32>,
}

/// Classify label volume `labels` on `grid` by `table`, alone or over `scalar` (a scalar volume
/// on the same grid, with its transfer function and shading), the two combined per voxel.
/// Refused: a label that is not a whole number in [0, `MAX_LABEL`], a grid of other dimensions.
pub fn classify_labels(
    grid: Grid,
    labels: &ScalarVolume,
    table: &LabelTable,
    scalar: Option<(&ScalarVolume, &TransferFunction, Option<Shading>)>,
) -> Result<Labelled> {
    table.validate()?;
    if labels.dims != grid.dims {
        return Err(Error::InvalidArgument(format!(
            "a {:?} label volume on a {:?} grid: they must match",
            labels.dims, grid.dims
        )));
    }
    if let Some(at) = labels.values.iter().position(|&v| !(v.fract() == 0.0 && (0.0..=MAX_LABEL as f32).contains(&v))) {
        return Err(Error::InvalidArgument(format!(
            "label volume: sample {at} is {}, not a label (a whole number from 0 to {MAX_LABEL})",
            labels.values[at]
        )));
    }
    // Dense lookup for the common case of small labels; the table's others by search.
    let mut lookup: Vec<Option<&crate::labels::Label>> = vec![None; 4096];
    for l in &table.labels {
        if (l.value as usize) < lookup.len() {
            lookup[l.value as usize] = Some(l);
        }
    }
    let entry = |v: u32| if (v as usize) < lookup.len() { lookup[v as usize] } else { table.get(v) };
    let mut missing = std::collections::BTreeMap::<u32, u64>::new();
    let [nx, ny, _] = grid.dims;
    let label_voxel = |i: u32, j: u32, k: u32, missing: &mut std::collections::BTreeMap<u32, u64>| {
        let v = labels.values[(i + nx * (j + ny * k)) as usize] as u32;
        match entry(v) {
            Some(l) if l.visible && l.opacity > 0.0 => {
                Some(([l.color[0], l.color[1], l.color[2], l.opacity], l.opacity))
            }
            Some(_) => None,
            None => {
                if v != 0 {
                    *missing.entry(v).or_default() += 1;
                }
                None
            }
        }
    };
    let set = match scalar {
        None => SplatSet::from_fn_valued(grid, |i, j, k| label_voxel(i, j, k, &mut missing))?,
        Some((vol, tf, shading)) => {
            // The scalar's own classification, then the label on top at each voxel.
            let under = crate::classify::classify_on(grid, vol, tf, shading)?;
            SplatSet::from_fn_valued(grid, |i, j, k| {
                let s = under.find(i, j, k).map(|s| {
                    let sp = &under.splats()[s];
                    (sp.color, f32::from_bits(sp.ijk[3]))
                });
                let l = label_voxel(i, j, k, &mut missing).map(|(c, _)| (c, 0.0));
                combine([s, l].into_iter())
            })?
        }
    };
    let unlabelled = missing.values().sum();
    Ok(Labelled {
        set: set.with_unlabelled(unlabelled),
        unlabelled,
        missing: missing.keys().take(8).copied().collect(),
    })
}
