//! A non-empty brick's header: where its records lie and its value range.

use bytemuck::{Pod, Zeroable};

/// A non-empty brick. Keep in step with the GPU side when it arrives (16 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct BrickHeader {
    /// Brick coordinates, 10 bits each: x | y << 10 | z << 20.
    pub brick: u32,
    /// Its first record.
    pub first: u32,
    /// Its records (at most `BRICK`³).
    pub count: u32,
    /// Its smallest and largest quantised value: min | max << 16.
    pub range: u32,
}

const _: () = assert!(std::mem::size_of::<BrickHeader>() == 16);

impl BrickHeader {
    /// The brick's coordinates in the brick grid.
    pub fn coords(&self) -> [u32; 3] {
        [self.brick & 1023, (self.brick >> 10) & 1023, self.brick >> 20]
    }
}
