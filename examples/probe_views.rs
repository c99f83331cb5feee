use glam::Vec3;
use voxsplat::*;
fn main() {
    let set = scene::build("cube60").unwrap();
    let mut r = Renderer::new(&RendererOptions::default()).unwrap();
    r.set_scene(set.clone()).unwrap();
    for (eye, tgt) in [
        ([20.0, 10.0, 60.0], [-40.0, 0.0, 0.0]),
        ([15.0, 20.0, 50.0], [-50.0, 0.0, -10.0]),
        ([10.0, 10.0, 45.0], [-60.0, 0.0, -10.0]),
        ([20.0, 40.0, 50.0], [-40.0, -10.0, -10.0]),
    ] {
        let cam = Camera {
            eye: Vec3::from(eye),
            target: Vec3::from(tgt),
            up: Vec3::Y,
            projection: Projection::Perspective { fov_y_deg: 75.0 },
            near: 0.5,
            far: 300.0,
            width: 200,
            height: 200,
        };
        let mut img = |k| {
            let mut ro = RenderOptions::default();
            ro.order = k;
            r.render(&cam, &ro).unwrap().image
        };
        let (b, w, p, s) = (img(OrderKind::Btf), img(OrderKind::Wbtf), img(OrderKind::Pbtf), img(OrderKind::Sorted));
        let d = |x: &cpu::ImageF32| output::diff_rgba8(x, &s).unwrap().0;
        println!("{eye:?} {tgt:?}: btf {:.2} wbtf {:.2} pbtf {:.2}", d(&b), d(&w), d(&p));
    }
}
