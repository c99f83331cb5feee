//! GPU timestamp queries: one pool, read back after the frame's fence.
use super::Context;
use crate::device::Timing;
use crate::error::{Error, Result};
use ash::vk;
use std::sync::Arc;

/// Timestamp queries.
pub struct Timer {
    ctx: Arc<Context>,
    pub(crate) pool: Option<vk::QueryPool>,
    pub(crate) capacity: u32,
}

impl Timer {
    /// A pool of `capacity` timestamps; inert when the device has no timestamps.
    pub fn new(ctx: &Arc<Context>, capacity: u32) -> Result<Self> {
        let pool = if matches!(ctx.choices().timing, Timing::Timestamps { .. }) {
            let info = vk::QueryPoolCreateInfo::default().query_type(vk::QueryType::TIMESTAMP).query_count(capacity);
            // SAFETY: valid create info.
            Some(unsafe { ctx.device.create_query_pool(&info, None) }.map_err(Error::vk("vkCreateQueryPool"))?)
        } else {
            None
        };
        Ok(Self { ctx: ctx.clone(), pool, capacity })
    }

    /// Milliseconds between consecutive written timestamps `0..count`; `None` without timestamps.
    pub fn read_ms(&self, count: u32) -> Result<Option<Vec<f64>>> {
        let (Some(pool), Timing::Timestamps { period_ns, mask }) = (self.pool, self.ctx.choices().timing) else {
            return Ok(None);
        };
        let count = count.min(self.capacity);
        if count < 2 {
            return Ok(Some(Vec::new()));
        }
        let mut ticks = vec![0u64; count as usize];
        // SAFETY: the queries were written by a submission that has completed (its fence waited).
        unsafe {
            self.ctx.device.get_query_pool_results(
                pool,
                0,
                &mut ticks,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }
        .map_err(Error::vk("vkGetQueryPoolResults"))?;
        // Counts hold `timestampValidBits` bits and wrap past them.
        Ok(Some(ticks.windows(2).map(|w| (w[1].wrapping_sub(w[0]) & mask) as f64 * period_ns * 1e-6).collect()))
    }
}

impl Drop for Timer {
    fn drop(&mut self) {
        if let Some(pool) = self.pool {
            // SAFETY: owners wait idle first.
            unsafe { self.ctx.device.destroy_query_pool(pool, None) };
        }
    }
}
