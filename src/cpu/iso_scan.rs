//! Mirror of `iso_scan.comp`: the rows' first splats (an exclusive scan in place), then the total.
use super::bindings::Bindings;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::IsoPush;

/// Exclusive scan of the first `rows` counts; `counts[rows]` gets the total.
pub fn iso_scan(rows: u32, counts: &mut [u32]) {
    let mut carry = 0u32;
    for c in &mut counts[..rows as usize] {
        let v = *c;
        *c = carry;
        carry += v;
    }
    counts[rows as usize] = carry;
}

pub(crate) fn stage(b: &mut Bindings<'_>, d: &Args, _: &Variant) -> Result<()> {
    let push: IsoPush = d.push_as();
    let mut counts = b.take(Res::IsoCounts);
    iso_scan(push.rows, &mut counts);
    b.put(Res::IsoCounts, counts);
    Ok(())
}
