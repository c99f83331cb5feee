//! Prints one 64-bit hash per EXR file of its pixels' exact f32 bits (EXR files themselves may
//! order their compressed blocks differently run to run). Used by scripts/image-hashes.sh.
use std::hash::{Hash, Hasher};

fn main() -> Result<(), voxsplat::Error> {
    for path in std::env::args().skip(1) {
        let image = voxsplat::output::read_image(path.as_ref())?;
        let mut h = std::collections::hash_map::DefaultHasher::new();
        (image.width, image.height).hash(&mut h);
        for p in &image.pixels {
            p.map(f32::to_bits).hash(&mut h);
        }
        println!("{:016x}", h.finish());
    }
    Ok(())
}
