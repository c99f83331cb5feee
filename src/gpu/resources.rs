//! The GPU's resources by name: per renderer (uniforms, kernel tables), per scene (splats, rows,
//! slice lists, ranks), per frame (every other `Res`, grown on demand) and the render target;
//! descriptor sets built from the stage table's binding lists and kept until a resource they name
//! is replaced.
use super::pipelines::{Pipelines, COLOR_FORMAT};
use crate::constants::{
    FOOTPRINT_TABLE_SIZE, MAX_GPU_SPLATS, PYRAMID_PAGE, RADIAL_TABLE_SIZE, RECORD_PAGE, RECORD_PAGES, SPLAT_PAGE,
};
use crate::error::{Error, Result};
use crate::gpu_types::{Frame, SplatParams};
use crate::kernel::Kernel;
use crate::plan::Prepared;
use crate::stages::{List, Res, StageId};
use crate::vk::{
    Bind, Buffer, BufferUsageFlags as BU, Context, DescriptorSet, Format, Framebuffer, Image, ImageLayout as IL,
    ImageUsageFlags as IU, Memory, Sampler, Stage,
};
use std::collections::HashMap;
use std::sync::Arc;

/// A scene on the device.
pub struct SceneBuffers {
    pub splats: Buffer,
    /// A rectilinear grid's x, y, z coordinates (one unused float on a uniform grid).
    pub coords: Buffer,
    pub row_start: Buffer,
    /// Slice-grouped draw lists of axes x, y, z.
    pub draw: [Buffer; 3],
    pub ranks: Buffer,
    /// The ray caster's 3D texture of (colour * tau, tau), and its brick occupancy (brick side,
    /// flags): built on first use.
    pub field: Option<Image>,
    /// Whether `field` is the projection modes' (`DenseField::projection`).
    pub field_kind: crate::plan::FieldKind,
    pub bricks: Option<(u32, Buffer)>,
    /// A bricked volume's store: headers, masks, records, brick index (`Res::BrickHeaders`..).
    pub store: Option<[Buffer; 4]>,
}

/// The images a frame draws into.
pub struct Target {
    pub width: u32,
    pub height: u32,
    pub layers: u32,
    pub color: Image,
    pub color_fb: Framebuffer,
    pub sums: Image,
    pub sums_fb: Framebuffer,
    pub accum: Image,
    /// The target and the accumulation image as the two time slots' attachments.
    pub slots_fb: Framebuffer,
}

pub struct Resources {
    ctx: Arc<Context>,
    pub frame: Buffer,
    /// The radial footprint table (`Kernel::radial_pairs`) and the kernel-slice table.
    pub radial: Buffer,
    pub slices: Image,
    pub sampler: Sampler,
    kernel: Option<Kernel>,
    scene: Option<SceneBuffers>,
    bufs: HashMap<Res, Buffer>,
    /// What a buffer kept across frames holds (`Engine::tag`); gone with the buffer.
    pub tags: HashMap<Res, u64>,
    target: Option<Target>,
    readback: HashMap<Res, Buffer>,
    sets: HashMap<(StageId, List), DescriptorSet>,
    /// Stands in for frame buffers not allocated yet (the stage in use never reads them).
    stand_in: Buffer,
}

const USAGE: BU = BU::from_raw(BU::STORAGE_BUFFER.as_raw() | BU::TRANSFER_SRC.as_raw() | BU::TRANSFER_DST.as_raw());

fn storage(ctx: &Arc<Context>, name: &str, data: &[u8]) -> Result<Buffer> {
    Buffer::with_data(ctx, name, data, BU::STORAGE_BUFFER)
}

/// The two bindings of a per-splat array of 80-byte records (`SPLAT_PAGE` records each, see
/// constants.rs); while the array fits in one page the second binding repeats the first.
fn pages(buf: &Buffer) -> [Bind<'_>; 2] {
    const PAGE: u64 = SPLAT_PAGE as u64 * std::mem::size_of::<SplatParams>() as u64;
    const _: () = assert!(std::mem::size_of::<SplatParams>() == std::mem::size_of::<crate::gpu_types::ScreenQuad>());
    let size = buf.size();
    let hi = if size > PAGE { Bind::Range(buf, PAGE, (size - PAGE).min(PAGE)) } else { Bind::Range(buf, 0, size) };
    [Bind::Range(buf, 0, size.min(PAGE)), hi]
}

/// Per-splat arrays are sized exactly (they are large and fixed per scene); lists whose length
/// changes every frame grow by powers of two.
fn exact(res: Res) -> bool {
    matches!(res, Res::Order | Res::Params | Res::Quads | Res::RowSplit | Res::Segments | Res::Fixed)
}

impl Resources {
    pub fn new(ctx: &Arc<Context>) -> Result<Self> {
        let frame = Buffer::new(ctx, "frame", std::mem::size_of::<Frame>() as u64, BU::STORAGE_BUFFER, Memory::Upload)?;
        let radial_bytes = RADIAL_TABLE_SIZE as u64 * 8;
        let radial = Buffer::new(ctx, "radial table", radial_bytes, BU::STORAGE_BUFFER, Memory::Upload)?;
        let n = FOOTPRINT_TABLE_SIZE;
        let slices =
            Image::new(ctx, "slice table", (n, n, 1), Format::R32_SFLOAT, IU::SAMPLED | IU::TRANSFER_DST, false)?;
        Ok(Self {
            ctx: ctx.clone(),
            frame,
            radial,
            slices,
            sampler: Sampler::nearest(ctx)?,
            kernel: None,
            scene: None,
            bufs: HashMap::new(),
            tags: HashMap::new(),
            target: None,
            readback: HashMap::new(),
            sets: HashMap::new(),
            stand_in: Buffer::new(ctx, "stand-in", 16, USAGE, Memory::Device)?,
        })
    }

    /// Upload a scene's splats, rows, slice lists and ranks; the previous scene's frame buffers go.
    /// `budget`: a bricked store that streams under it (`BrickScene::streams`) keeps its records
    /// on the host.
    pub fn set_scene(&mut self, prep: &Prepared, budget: u64) -> Result<()> {
        self.ctx.wait_idle();
        self.sets.clear();
        self.bufs.clear();
        self.tags.clear();
        self.scene = None;
        let set = &prep.set;
        // A set past the splat cap is only ray cast on the device (splat frames refuse it,
        // `check_splat_cap`): its splat arrays stay on the host, one-element stand-ins bound.
        let splats = set.len() <= MAX_GPU_SPLATS as usize;
        fn or_one(splats: bool, words: &[u32]) -> &[u32] {
            if splats {
                words
            } else {
                &[0; 8]
            }
        }
        if let Some(b) = prep.bricks.as_ref().filter(|b| !b.streams(budget)) {
            let most = RECORD_PAGE as u64 * RECORD_PAGES as u64;
            if b.store.records.len() as u64 > most {
                return Err(Error::TooLarge(format!(
                    "a bricked store of {} voxels: the GPU path binds at most {most} ({RECORD_PAGES} storage bindings \
                     of {RECORD_PAGE} records)",
                    b.store.records.len()
                )));
            }
        }
        let ctx = &self.ctx;
        self.scene = Some(SceneBuffers {
            splats: storage(ctx, "splats", bytemuck::cast_slice(or_one(splats, bytemuck::cast_slice(set.splats()))))?,
            coords: storage(
                ctx,
                "coords",
                bytemuck::cast_slice(&set.coordinates().map_or(vec![0.0f32], |c| c.concat())),
            )?,
            row_start: storage(ctx, "row_start", bytemuck::cast_slice(or_one(splats, set.row_start())))?,
            draw: [
                storage(ctx, "slices x", bytemuck::cast_slice(or_one(splats, &prep.slices[0].1)))?,
                storage(ctx, "slices y", bytemuck::cast_slice(or_one(splats, &prep.slices[1].1)))?,
                storage(ctx, "slices z", bytemuck::cast_slice(or_one(splats, &prep.slices[2].1)))?,
            ],
            ranks: storage(ctx, "sheet ranks", bytemuck::cast_slice(or_one(splats, &prep.ranks)))?,
            field: None,
            field_kind: crate::plan::FieldKind::Composite,
            bricks: None,
            store: match &prep.bricks {
                // At least one word each: a TF that leaves nothing must not make a zero-sized buffer.
                Some(b) => {
                    let s = &b.store;
                    let words = |v: &[u32]| if v.is_empty() { vec![0u32] } else { v.to_vec() };
                    Some([
                        storage(ctx, "brick headers", bytemuck::cast_slice(&words(bytemuck::cast_slice(&s.headers))))?,
                        storage(ctx, "brick masks", bytemuck::cast_slice(&words(&s.mask_words())))?,
                        // Copied from when a time point's records outgrow it (`patch_store`).
                        Buffer::with_data(
                            ctx,
                            "brick records",
                            bytemuck::cast_slice(&words(if b.streams(budget) { &[] } else { &s.records })),
                            USAGE,
                        )?,
                        storage(ctx, "brick index", bytemuck::cast_slice(&words(&b.index_words())))?,
                    ])
                }
                None => None,
            },
        });
        Ok(())
    }

    /// Follow a bricked store's `patch` (`BrickScene::update`): the changed headers, masks and
    /// records rewritten in place, a buffer replaced only when the brick set changed or the records
    /// outgrew theirs (then with a quarter to spare, for the next time points' moved bricks).
    /// Returns the bytes written.
    pub fn patch_store(&mut self, prep: &Prepared, patch: &crate::bricks::Patch, budget: u64) -> Result<u64> {
        let b = prep.bricks.as_ref().ok_or_else(|| Error::InvalidArgument("the scene is not bricked".into()))?;
        let (s, streams) = (&b.store, b.streams(budget));
        let most = RECORD_PAGE as u64 * RECORD_PAGES as u64;
        if !streams && s.records.len() as u64 > most {
            return Err(Error::TooLarge(format!(
                "a bricked store of {} records: the GPU path binds at most {most}",
                s.records.len()
            )));
        }
        self.ctx.wait_idle();
        let ctx = self.ctx.clone();
        let scene = self.scene.as_mut().ok_or_else(|| Error::InvalidArgument("no scene on the device".into()))?;
        // The ray caster's field and its occupancy hold the old values.
        (scene.field, scene.bricks) = (None, None);
        let store = scene.store.as_mut().ok_or_else(|| Error::InvalidArgument("the scene is not bricked".into()))?;
        let words = |v: &[u32]| if v.is_empty() { vec![0u32] } else { v.to_vec() };
        let masks = s.mask_words();
        let (mut written, mut replaced) = (0u64, false);
        if patch.layout {
            let index = b.index_words();
            store[0] = storage(&ctx, "brick headers", bytemuck::cast_slice(&words(bytemuck::cast_slice(&s.headers))))?;
            store[1] = storage(&ctx, "brick masks", bytemuck::cast_slice(&words(&masks)))?;
            store[3] = storage(&ctx, "brick index", bytemuck::cast_slice(&words(&index)))?;
            written += (s.headers.len() * 16 + masks.len() * 4 + index.len() * 4) as u64;
            replaced = true;
        } else {
            let per = masks.len() / s.headers.len().max(1);
            for &h in &patch.headers {
                let h = h as usize;
                store[0].write_at(h as u64 * 16, bytemuck::bytes_of(&s.headers[h]))?;
                store[1].write_at((h * per * 4) as u64, bytemuck::cast_slice(&masks[h * per..(h + 1) * per]))?;
                written += 16 + per as u64 * 4;
            }
        }
        let need = s.records.len() as u64 * 4;
        if streams {
            // Records travel batch by batch (the record cache dropped the changed bricks).
            if store[2].size() > 16 {
                store[2] = storage(&ctx, "brick records", bytemuck::cast_slice(&[0u32]))?;
                replaced = true;
            }
        } else {
            let stand_in = store[2].size() == 16 && need > 16;
            if patch.compacted || stand_in || store[2].size() < need {
                let size = (need + need / 4).clamp(need.max(4), most * 4);
                let buf = Buffer::new(&ctx, "brick records", size, USAGE, Memory::Upload)?;
                if !(patch.compacted || stand_in) {
                    // The records that stay keep their places: copied on the device, not sent again.
                    ctx.submit(|rec| {
                        rec.copy_buffer(&store[2], &buf, store[2].size());
                        Ok(())
                    })?;
                }
                (store[2], replaced) = (buf, true);
            }
            for &[first, n] in &patch.records {
                let r = &s.records[first as usize..(first + n) as usize];
                store[2].write_at(first as u64 * 4, bytemuck::cast_slice(r))?;
                written += n as u64 * 4;
            }
        }
        if replaced {
            self.sets.clear();
        }
        Ok(written)
    }

    /// Refuse a splat frame of a set past the GPU path's splat cap (it may still be ray cast).
    pub fn check_splat_cap(prep: &Prepared) -> Result<()> {
        let n = prep.set.len();
        if prep.bricks.is_none() && n > MAX_GPU_SPLATS as usize {
            return Err(Error::TooLarge(format!(
                "{n} splats: the GPU path takes at most {MAX_GPU_SPLATS} (two {SPLAT_PAGE}-record pages of 80-byte \
                 per-splat parameters; one storage binding is limited to maxStorageBufferRange). Classify fewer \
                 voxels as non-empty, draw the volume as a bricked store, use the CPU backend (--cpu) or cast rays"
            )));
        }
        Ok(())
    }

    pub fn scene(&self) -> Result<&SceneBuffers> {
        self.scene.as_ref().ok_or_else(|| Error::InvalidArgument("no scene: call set_scene first".into()))
    }

    pub fn scene_mut(&mut self) -> Result<&mut SceneBuffers> {
        self.scene.as_mut().ok_or_else(|| Error::InvalidArgument("no scene: call set_scene first".into()))
    }

    /// Upload the kernel's tables unless they are already there.
    pub fn set_kernel(&mut self, kernel: Kernel) -> Result<()> {
        if self.kernel == Some(kernel) {
            return Ok(());
        }
        self.radial.write(bytemuck::cast_slice(&kernel.radial_pairs()))?;
        let slice = kernel.slice_table();
        let staging =
            Buffer::with_data(&self.ctx, "slice table staging", bytemuck::cast_slice(&slice), BU::TRANSFER_SRC)?;
        let table = &self.slices;
        self.ctx.submit(|rec| {
            rec.transition(table, IL::UNDEFINED, IL::TRANSFER_DST_OPTIMAL, Stage::All, Stage::Transfer);
            rec.copy_buffer_to_image(&staging, table);
            rec.transition(table, IL::TRANSFER_DST_OPTIMAL, IL::SHADER_READ_ONLY_OPTIMAL, Stage::Transfer, Stage::All);
            Ok(())
        })?;
        // Sets name the table objects, not their contents: no rebinding.
        self.kernel = Some(kernel);
        Ok(())
    }

    /// Forget every descriptor set (a resource they name is being replaced).
    pub fn clear_sets(&mut self) {
        self.sets.clear();
    }

    /// Whether `res` must be replaced to hold `bytes` (pending work naming it must run first).
    pub fn must_grow(&self, res: Res, bytes: u64) -> bool {
        !res.is_image() && !res.is_constant() && self.bufs.get(&res).is_none_or(|b| b.size() < bytes)
    }

    /// Make `res` hold at least `bytes`.
    pub fn ensure(&mut self, res: Res, bytes: u64) -> Result<()> {
        if !self.must_grow(res, bytes) {
            return Ok(());
        }
        let bytes = bytes.max(4);
        let range = self.ctx.max_storage_range();
        let size = if exact(res) || bytes > range { bytes } else { bytes.next_power_of_two().min(range) };
        self.sets.clear();
        self.bufs.remove(&res);
        self.tags.remove(&res);
        self.bufs.insert(res, Buffer::new(&self.ctx, &format!("{res:?}"), size, USAGE, Memory::Device)?);
        Ok(())
    }

    /// A frame buffer (or a per-renderer/per-scene one) by name.
    pub fn buffer(&self, res: Res) -> Result<&Buffer> {
        let scene = || self.scene();
        Ok(match res {
            Res::Frame => &self.frame,
            Res::Radial => &self.radial,
            Res::Splats => &scene()?.splats,
            Res::Coords => &scene()?.coords,
            Res::RowStart => &scene()?.row_start,
            Res::Ranks => &scene()?.ranks,
            Res::BrickHeaders | Res::BrickMasks | Res::BrickRecords | Res::BrickIndex => {
                let store =
                    scene()?.store.as_ref().ok_or_else(|| Error::InvalidArgument("the scene is not bricked".into()))?;
                &store[match res {
                    Res::BrickHeaders => 0,
                    Res::BrickMasks => 1,
                    Res::BrickRecords => 2,
                    _ => 3,
                }]
            }
            other => self
                .bufs
                .get(&other)
                .ok_or_else(|| Error::InvalidArgument(format!("{other:?} is not allocated in this frame")))?,
        })
    }

    /// Bytes a frame buffer holds (0 when absent).
    pub fn size(&self, res: Res) -> u64 {
        self.bufs.get(&res).map(|b| b.size()).unwrap_or(0)
    }

    /// The images for a `width` x `height` frame with `layers` summation layers (replaced when
    /// any of them differs).
    pub fn target(&mut self, pipes: &Pipelines, width: u32, height: u32, layers: u32) -> Result<&Target> {
        let same = self.target.as_ref().is_some_and(|t| (t.width, t.height, t.layers) == (width, height, layers));
        if !same {
            self.ctx.wait_idle();
            self.sets.clear();
            self.target = None;
            let ctx = &self.ctx;
            // Storage too: `present.comp` reads it.
            let usage = IU::COLOR_ATTACHMENT | IU::STORAGE | IU::TRANSFER_SRC;
            let color = Image::new(ctx, "color", (width, height, 1), COLOR_FORMAT, usage, false)?;
            let color_fb = Framebuffer::new(ctx, &pipes.target_pass, &color)?;
            let usage = IU::COLOR_ATTACHMENT | IU::STORAGE | IU::TRANSFER_SRC;
            let sums = Image::new(ctx, "sheet sums", (width, height, layers), COLOR_FORMAT, usage, true)?;
            let sums_fb = Framebuffer::new(ctx, &pipes.sheet_pass, &sums)?;
            let usage = IU::STORAGE | IU::TRANSFER_SRC | IU::TRANSFER_DST | IU::COLOR_ATTACHMENT;
            let accum = Image::new(ctx, "accumulation", (width, height, 1), COLOR_FORMAT, usage, false)?;
            let slots_fb = Framebuffer::over(ctx, &pipes.slots_pass, &[&color, &accum])?;
            self.target = Some(Target { width, height, layers, color, color_fb, sums, sums_fb, accum, slots_fb });
        }
        self.current_target()
    }

    pub fn current_target(&self) -> Result<&Target> {
        self.target.as_ref().ok_or_else(|| Error::InvalidArgument("nothing rendered yet".into()))
    }

    /// A host-readable buffer of at least `bytes` for `res`'s readback.
    pub fn ensure_readback(&mut self, res: Res, bytes: u64) -> Result<()> {
        if self.readback.get(&res).is_some_and(|b| b.size() >= bytes) {
            return Ok(());
        }
        self.readback.remove(&res);
        let size = bytes.max(4).next_power_of_two();
        let buf = Buffer::new(&self.ctx, &format!("{res:?} readback"), size, BU::TRANSFER_DST, Memory::Readback)?;
        self.readback.insert(res, buf);
        Ok(())
    }

    pub fn readback(&self, res: Res) -> Result<&Buffer> {
        self.readback.get(&res).ok_or_else(|| Error::InvalidArgument(format!("no readback for {res:?}")))
    }

    /// Build the descriptor set of `stage` with `list` as its draw list unless it exists.
    pub fn ensure_set(&mut self, pipes: &Pipelines, stage: StageId, list: List) -> Result<()> {
        if self.sets.contains_key(&(stage, list)) {
            return Ok(());
        }
        let set = self.build_set(pipes, stage, list)?;
        self.sets.insert((stage, list), set);
        Ok(())
    }

    pub fn set(&self, stage: StageId, list: List) -> Result<&DescriptorSet> {
        self.sets.get(&(stage, list)).ok_or_else(|| Error::InvalidArgument(format!("no set for {stage:?}")))
    }

    fn build_set(&self, pipes: &Pipelines, stage: StageId, list: List) -> Result<DescriptorSet> {
        let target = self.current_target()?;
        let frame_buf = |res: Res| self.bufs.get(&res).unwrap_or(&self.stand_in);
        let mut binds = Vec::new();
        for &res in stage.desc().bindings {
            binds.push(match res {
                Res::SliceTable => Bind::Texture(&self.slices, &self.sampler),
                Res::Field => match &self.scene()?.field {
                    Some(field) => Bind::Texture(field, &self.sampler),
                    None => return Err(Error::InvalidArgument("the ray caster's field is not uploaded".into())),
                },
                Res::Bricks => match &self.scene()?.bricks {
                    Some((_, bricks)) => Bind::Buffer(bricks),
                    None => return Err(Error::InvalidArgument("the ray caster's bricks are not uploaded".into())),
                },
                Res::Accum => Bind::Image(&target.accum),
                Res::Sums => Bind::Image(&target.sums),
                Res::Color => Bind::Image(&target.color),
                Res::Params | Res::ParamsHi | Res::Quads | Res::QuadsHi => {
                    let base = if matches!(res, Res::Params | Res::ParamsHi) { Res::Params } else { Res::Quads };
                    let [lo, hi] = pages(frame_buf(base));
                    if matches!(res, Res::Params | Res::Quads) {
                        lo
                    } else {
                        hi
                    }
                }
                Res::DrawList => Bind::Buffer(match list {
                    List::Order => frame_buf(Res::Order),
                    List::Slices(axis) => &self.scene()?.draw[axis as usize],
                    List::SlabPairs => frame_buf(Res::SlabPairs),
                }),
                page if page.pyramid_page().is_some() => {
                    page_range(frame_buf(Res::Pyramid), page.pyramid_page().unwrap_or(0), PYRAMID_PAGE)
                }
                page if page.record_page().is_some() => {
                    page_range(self.buffer(Res::BrickRecords)?, page.record_page().unwrap_or(0), RECORD_PAGE)
                }
                Res::Frame
                | Res::Radial
                | Res::Splats
                | Res::Coords
                | Res::RowStart
                | Res::Ranks
                | Res::BrickHeaders
                | Res::BrickMasks
                | Res::BrickIndex => Bind::Buffer(self.buffer(res)?),
                other => Bind::Buffer(frame_buf(other)),
            });
        }
        pipes.stages[stage as usize].layout.bind(&binds)
    }
}

impl Drop for Resources {
    fn drop(&mut self) {
        // Resources free themselves; make sure the GPU is done with them first.
        self.ctx.wait_idle();
    }
}

/// Page `k` of `words`-word pages of `buf` as a binding, or page 0 again past its end (one storage
/// binding may not pass maxStorageBufferRange).
fn page_range(buf: &Buffer, k: u64, words: u32) -> Bind<'_> {
    let page = words as u64 * 4;
    let (size, at) = (buf.size(), k * page);
    if at < size {
        Bind::Range(buf, at, (size - at).min(page))
    } else {
        Bind::Range(buf, 0, size.min(page))
    }
}
