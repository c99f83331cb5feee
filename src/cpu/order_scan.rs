//! Mirror of `glsl/order_scan.comp` (the `order_scan` stage); shared helpers in `order.rs`.
use super::bindings::Bindings;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::Frame;

/// Pass 2: exclusive prefix sum in place.
pub fn order_scan(frame: &Frame, segments: &mut [u32]) {
    let count = (2 * frame.dims[1] * frame.dims[2]) as usize;
    let mut carry = 0u32;
    for v in segments[..count].iter_mut() {
        let x = *v;
        *v = carry;
        carry += x;
    }
}

pub(crate) fn stage(b: &mut Bindings<'_>, _: &Args, _: &Variant) -> Result<()> {
    let mut segments = b.take(Res::Segments);
    order_scan(&b.frame, &mut segments);
    b.put(Res::Segments, segments);
    Ok(())
}
