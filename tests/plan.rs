//! The frame's plan and the stages' named builds, checked without a device: what `plan::frame`
//! decides for each mode, and what `Dispatch::new` refuses.
use super::common;
use crate::builds::{
    Build, CompositeLayers, Footprint, Only, Pages, Records, SheetMode, SheetTiles, TileComposite, TileOrder, TABLES,
};
use crate::dispatch::{Blend, Limits, List};
use crate::gpu_types::BrickPush;
use crate::options::{BlurProfile, Composite, Motion};
use crate::plan::{Draw, OrderSource, Prepared, SplatRaster};
use crate::stages::{Dispatch, Kind, StageId};
use crate::{scene, Camera, Direction, Error, OrderKind, Raster, RenderOptions};

const LIMITS: Limits =
    Limits { max_layers: 2048, max_storage_range: 1 << 31, budget_bytes: 1 << 30, target_depth: None };

fn options(raster: Raster, direction: Direction) -> RenderOptions {
    let mut o = RenderOptions::default();
    (o.raster, o.direction) = (raster, Some(direction));
    o
}

#[test]
fn every_build_is_its_own_row() {
    for t in TABLES {
        assert_eq!(t.builds.len(), t.variants.len());
        for (i, b) in t.builds.iter().enumerate() {
            assert_eq!(t.index(*b), Some(i), "{b:?} twice");
            for (j, v) in t.variants.iter().enumerate().filter(|(j, _)| *j != i) {
                let same =
                    v.defines == t.variants[i].defines && v.spec == t.variants[i].spec && v.draw == t.variants[i].draw;
                assert!(!same, "{b:?} and {:?} are one build", t.builds[j]);
            }
        }
    }
    // A stage's builds are of its kind: a draw's carry raster state, a compute stage's none.
    for id in StageId::ALL {
        let d = id.desc();
        for v in d.builds.variants {
            assert_eq!(v.draw.is_some(), d.kind == Kind::Draw, "{}", d.name);
        }
    }
}

#[test]
fn product_builds_list_every_combination() {
    let has = |stage: StageId, b: Build| stage.desc().builds.index(b).is_some();
    for pages in [Pages::One, Pages::Two] {
        for order in [TileOrder::BackToFront, TileOrder::FrontToBack, TileOrder::Terminating] {
            for blur in [false, true] {
                assert!(has(StageId::TileComposite, TileComposite { pages, order, blur, depth: false }.into()));
            }
            assert!(has(StageId::TileComposite, TileComposite { pages, order, blur: false, depth: true }.into()));
        }
    }
    for mode in [SheetMode::Axis, SheetMode::Slab, SheetMode::Binned] {
        assert!(has(StageId::FootprintSum, mode.into()));
        for points in [false, true] {
            assert!(has(StageId::SheetTiles, SheetTiles { mode, points }.into()));
            assert!(has(StageId::Footprint, Footprint::Sheet { mode, points }.into()));
        }
    }
    for blend in [Blend::Over, Blend::Under] {
        assert!(has(StageId::Footprint, Footprint::Slots(blend).into()));
        for points in [false, true] {
            assert!(has(StageId::Footprint, Footprint::Ordered { blend, points }.into()));
        }
    }
    // Summation is no ordered blend.
    assert!(!has(StageId::Footprint, Footprint::Ordered { blend: Blend::Add, points: false }.into()));
    for r in [Records::OnePage, Records::Paged, Records::Streamed] {
        assert!(has(StageId::BrickOrder, r.into()) && has(StageId::BrickParams, r.into()));
    }
}

#[test]
fn a_dispatch_refuses_a_build_its_stage_lacks_or_a_push_of_another_size() {
    let push = BrickPush::default();
    let bytes = bytemuck::bytes_of(&push);
    let ok = Dispatch::new(StageId::BrickParams, Records::Gradients, [1, 1, 1], List::Order, bytes).unwrap();
    assert_eq!(ok.variant().defines, "GRADIENTS");
    // Only brick_params and brick_pyramid read precomputed differences.
    let err = Dispatch::new(StageId::BrickOrder, Records::Gradients, [1, 1, 1], List::Order, bytes).unwrap_err();
    assert!(matches!(err, Error::Unsupported(_)) && err.to_string().contains("brick_order"), "{err}");
    // Another stage's type of build.
    assert!(Dispatch::new(StageId::Footprint, Pages::One, [0, 1, 0], List::Order, &[0; 64]).is_err());
    assert!(Dispatch::new(StageId::Composite, Only, [1, 1, 1], List::Order, &[0; 32]).is_err());
    assert!(Dispatch::new(StageId::OrderCount, CompositeLayers::Fixed, [1, 1, 1], List::Order, &[]).is_err());
    // The right build with push constants of the wrong size.
    let err = Dispatch::new(StageId::BrickOrder, Records::OnePage, [1, 1, 1], List::Order, &bytes[..8]).unwrap_err();
    assert!(matches!(err, Error::InvalidArgument(_)), "{err}");
    assert!(Dispatch::new(StageId::OrderCount, Only, [1, 1, 1], List::Order, &[0; 4]).is_err());
}

#[test]
fn a_dense_frame_plans_its_order_and_raster() {
    let set = scene::build("cube40").unwrap();
    let cam = Camera::framing(set.grid(), 96, 80);
    let prep = Prepared::new(set);
    let splats = prep.set.len() as u32;
    let plan_of = |o: &RenderOptions| crate::plan::frame(&prep, &cam, o, &LIMITS).unwrap();

    let p = plan_of(&options(Raster::Compute, Direction::FrontToBack));
    let Draw::Splats { splats: n, order, raster: SplatRaster::Tiles(rule), .. } = p.draw else { panic!("{p}") };
    assert_eq!((n, order), (splats, OrderSource::Pbtf));
    assert_eq!(rule.composite.order, TileOrder::Terminating, "the default threshold ends opaque tiles");
    assert_eq!(rule.push.count, splats);
    assert!(rule.push.chunks >= 1 && rule.push.chunks <= rule.most_chunks);

    let mut o = options(Raster::Compute, Direction::FrontToBack);
    o.early_termination = 0.0;
    let Draw::Splats { raster: SplatRaster::Tiles(rule), .. } = plan_of(&o).draw else { panic!() };
    assert_eq!((rule.composite.order, rule.push.occluded), (TileOrder::FrontToBack, 0.0));
    let Draw::Splats { raster: SplatRaster::Tiles(rule), .. } =
        plan_of(&options(Raster::Compute, Direction::BackToFront)).draw
    else {
        panic!()
    };
    assert_eq!((rule.composite.order, rule.push.occluded), (TileOrder::BackToFront, 0.0));

    let Draw::Splats { raster, .. } = plan_of(&options(Raster::Points, Direction::BackToFront)).draw else { panic!() };
    assert_eq!(raster, SplatRaster::Draw(Footprint::Ordered { blend: Blend::Over, points: true }));
    let Draw::Splats { raster, .. } = plan_of(&options(Raster::Graphics, Direction::FrontToBack)).draw else {
        panic!()
    };
    assert_eq!(raster, SplatRaster::Draw(Footprint::Ordered { blend: Blend::Under, points: false }));

    let mut o = options(Raster::Graphics, Direction::BackToFront);
    o.order = OrderKind::Sorted;
    let Draw::Splats { order, .. } = plan_of(&o).draw else { panic!() };
    assert_eq!(order, OrderSource::Host(OrderKind::Sorted));

    // A slotted blur draws both halves of the shutter; a tapered one per splat.
    let mut o = options(Raster::Graphics, Direction::BackToFront);
    let mut motion = Motion::straight(glam::Mat4::from_translation(glam::Vec3::X), 0.5);
    motion.profile = BlurProfile::Slotted;
    o.motion = Some(motion);
    let Draw::Splats { raster, .. } = plan_of(&o).draw else { panic!() };
    assert_eq!(raster, SplatRaster::Draw(Footprint::Slots(Blend::Over)));
    // The plan prints what it decided.
    let text = plan_of(&options(Raster::Compute, Direction::FrontToBack)).to_string();
    assert!(text.contains("compute tiles") && text.contains("PBTF"), "{text}");
}

#[test]
fn sheet_batches_stay_within_the_layer_limit_and_cover_the_list() {
    let set = scene::build("cube40").unwrap();
    let cam = Camera::framing(set.grid(), 96, 80);
    let prep = Prepared::new(set);
    let splats = prep.set.len() as u32;
    for (max_layers, raster, direction) in [
        (3, Raster::Graphics, Direction::FrontToBack),
        (2048, Raster::Points, Direction::BackToFront),
        (5, Raster::Compute, Direction::FrontToBack),
    ] {
        let limits = Limits { max_layers, ..LIMITS };
        let mut o = options(raster, direction);
        o.composite = Composite::Sheet;
        let p = crate::plan::frame(&prep, &cam, &o, &limits).unwrap();
        let Draw::Sheets { pass, axis, .. } = &p.draw else { panic!("{p}") };
        assert_eq!(pass.list, List::Slices(*axis as u8));
        assert!(pass.layers <= max_layers, "{} layers", pass.layers);
        if max_layers < 10 {
            assert!(pass.batches.len() >= 40 / max_layers as usize, "{} batches", pass.batches.len());
        }
        assert!(pass.batches.iter().all(|b| b.layers >= 1 && b.layers <= pass.layers));
        assert_eq!(pass.batches.iter().map(|b| b.instances).sum::<u32>(), splats, "every splat in one batch");
        let threshold = if direction == Direction::FrontToBack { o.early_termination } else { 0.0 };
        assert!(pass.batches.iter().all(|b| b.push.occluded == threshold));
        assert_eq!((pass.compute, pass.points), (raster == Raster::Compute, raster == Raster::Points));
    }
    // Slabs: the geometry now, the batches once the binning's counts are back.
    let mut o = options(Raster::Graphics, Direction::FrontToBack);
    o.composite = Composite::Slab;
    let p = crate::plan::frame(&prep, &cam, &o, &LIMITS).unwrap();
    let Draw::Slabs { geometry, pass, .. } = &p.draw else { panic!("{p}") };
    assert!(geometry.slabs > 1 && pass.batches.is_empty() && pass.list == List::SlabPairs);
    assert!(p.to_string().contains("cut after the binning"));
}

#[test]
fn a_bricked_plan_streams_only_under_a_short_budget() {
    let vol = common::blob([96, 96, 96]);
    let cam = Camera::framing(&crate::Grid::centered(vol.dims, vol.spacing).unwrap(), 80, 80);
    let mut r = common::cpu();
    r.set_volume(&vol, &common::blob_tf(), None).unwrap();
    let scene = r.volume().unwrap().clone();
    let least = crate::plan::bricked_min_budget(&scene, u64::MAX, 80, 80);
    let records = scene.store.records.len() as u64 * 4;
    let o = options(Raster::Compute, Direction::FrontToBack);
    for lod in [crate::Lod::Auto, crate::Lod::Off] {
        let mut o = o.clone();
        o.lod = lod;
        // Plenty: resident, one page of records.
        let p = r.plan(&cam, &o).unwrap();
        let Draw::Bricked(b) = &p.draw else { panic!("{p}") };
        assert!(!b.streamed && b.build == Records::OnePage && b.lod == (lod == crate::Lod::Auto), "{p}");
        assert!(b.terminating && b.cull_hidden && b.sheets.is_none());
        // Below the least budget (the images alone take more): refused with the minimum named.
        assert!(least > 1 << 16);
        r.set_gpu_budget(1 << 16).unwrap();
        let err = r.plan(&cam, &o).unwrap_err();
        assert!(matches!(err, Error::TooLarge(_)) && err.to_string().contains("the minimum is"), "{err}");
        r.set_gpu_budget(1 << 30).unwrap();
    }
    // A budget under twice the records streams them (levels of detail off: no pyramid to hold).
    let budget = 2 * records - 1;
    let streamed_least = crate::plan::bricked_min_budget(&scene, budget, 80, 80);
    assert!(scene.streams(budget) && budget >= streamed_least, "{budget} {streamed_least}");
    r.set_gpu_budget(budget).unwrap();
    let mut o = o.clone();
    o.lod = crate::Lod::Off;
    let p = r.plan(&cam, &o).unwrap();
    let Draw::Bricked(b) = &p.draw else { panic!("{p}") };
    assert!(b.streamed && b.build == Records::Streamed && b.cache_slots > 0, "{p}");
    assert!(p.to_string().contains("streamed"));
    r.set_gpu_budget(1 << 30).unwrap();
    // Sheets over bricks: their layers come out of the budget.
    let mut o = options(Raster::Graphics, Direction::FrontToBack);
    o.composite = Composite::Sheet;
    let p = r.plan(&cam, &o).unwrap();
    let Draw::Bricked(b) = &p.draw else { panic!("{p}") };
    let s = b.sheets.as_ref().expect("sheets planned");
    assert!(s.axis_sheets && s.available < b.available && !b.lod, "{p}");
}
