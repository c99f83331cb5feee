//! What a labelled or multichannel scene is classified from: the label volume with its table
//! (over a scalar volume or alone), or each channel with its transfer function. `render` classifies
//! them once; the viewer keeps them to classify again as its panel shows or hides a label or a
//! channel, or changes a label's colour and opacity.
use super::{headlight, load_tf, load_volume_parts, transfer_function, volume_hints};
use crate::scene_args::SceneArgs;
use voxsplat::classify::{Shading, TransferFunction};
use voxsplat::labels::LabelTable;
use voxsplat::orient::Orientation;
use voxsplat::volume::ScalarVolume;
use voxsplat::{Error, Grid, Result, SplatSet};

/// A scalar volume drawn under the labels: its transfer function and shading.
pub type Under = (ScalarVolume, TransferFunction, Option<Shading>);

pub enum Parts {
    /// `--labels` with `--label-table`, alone or over the `--volume`.
    Labels { grid: Grid, labels: ScalarVolume, table: LabelTable, under: Option<Under> },
    /// The `--volume`'s channels and the `--channel` files, each with its transfer function and
    /// whether it is drawn.
    Channels { grid: Grid, channels: Vec<(ScalarVolume, TransferFunction, bool)>, shading: Option<Shading> },
}

impl Parts {
    /// The parts `a` names, if it names labels or channels.
    pub fn load(a: &SceneArgs, orientation: Option<Orientation>) -> Result<Option<Self>> {
        if let Some(path) = &a.labels {
            let table_path =
                a.label_table.as_ref().ok_or_else(|| Error::InvalidArgument("--labels needs --label-table".into()))?;
            let text = std::fs::read_to_string(table_path)
                .map_err(|e| Error::InvalidArgument(format!("{}: {e}", table_path.display())))?;
            let table = LabelTable::from_toml(&text)?;
            let labels = voxsplat::loaders::load_volume(path, &Default::default())?;
            let (grid, under) = match &a.volume {
                Some(v) => {
                    let (vol, tf, shading) = load_volume_parts(a, v, orientation)?;
                    (
                        voxsplat::orient::placed_grid(vol.dims, vol.spacing, orientation.as_ref())?,
                        Some((vol, tf, shading)),
                    )
                }
                None => (voxsplat::orient::placed_grid(labels.dims, labels.spacing, None)?, None),
            };
            return Ok(Some(Parts::Labels { grid, labels, table, under }));
        }
        let Some(path) = a.volume.as_ref().filter(|_| !(a.channels.is_empty() && a.channel_tfs.is_empty())) else {
            return Ok(None);
        };
        let mut volumes = voxsplat::loaders::load_channels(path, &volume_hints(a)?)?;
        let in_file = volumes.len();
        for p in &a.channels {
            volumes.extend(voxsplat::loaders::load_channels(p, &Default::default())?);
        }
        if a.channel_tfs.len() + 1 != volumes.len() {
            return Err(Error::InvalidArgument(format!(
                "{} channels ({in_file} in --volume, {} --channel files) and {} --channel-tf: give each channel after \
                 the first its transfer function",
                volumes.len(),
                a.channels.len(),
                a.channel_tfs.len()
            )));
        }
        let mut tfs = vec![transfer_function(a)?];
        for t in &a.channel_tfs {
            tfs.push(load_tf(t)?);
        }
        let first = &volumes[0];
        let grid = voxsplat::orient::placed_grid(first.dims, first.spacing, orientation.as_ref())?;
        let shading = headlight(a, first.dims, first.spacing, orientation);
        let channels = volumes.into_iter().zip(tfs).map(|(v, tf)| (v, tf, true)).collect();
        Ok(Some(Parts::Channels { grid, channels, shading }))
    }

    /// The splats: labels over their scalar volume, or the drawn channels added per voxel (none
    /// drawn: no splat). `report`: say on stderr how many voxels have a label the table lacks.
    pub fn classify(&self, report: bool) -> Result<SplatSet> {
        match self {
            Parts::Labels { grid, labels, table, under } => {
                let under = under.as_ref().map(|(v, tf, s)| (v, tf, *s));
                let labelled = voxsplat::labels::classify_labels(*grid, labels, table, under)?;
                if report && labelled.unlabelled > 0 {
                    let list: Vec<String> = labelled.missing.iter().map(u32::to_string).collect();
                    eprintln!(
                        "{} voxels hidden: their labels ({}{}) are not in the label table",
                        labelled.unlabelled,
                        list.join(", "),
                        if labelled.missing.len() == 8 { ", ..." } else { "" }
                    );
                }
                Ok(labelled.set)
            }
            Parts::Channels { grid, channels, shading } => {
                let drawn: Vec<_> = channels.iter().filter(|c| c.2).map(|(v, tf, _)| (v, tf)).collect();
                if drawn.is_empty() {
                    return SplatSet::empty(*grid);
                }
                voxsplat::classify::classify_channels(*grid, &drawn, *shading)
            }
        }
    }
}
