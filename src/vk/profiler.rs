//! GPU timing and counting: one timestamp pool and one pipeline-statistics pool,
//! reset at the start of every frame's command buffer and read after its fence.
//!
//! Each pass gets three timestamps: before its barriers, after its barriers
//! (the pass starts), and after its commands. Barrier time is reported on its own
//! and never charged to the pass.

use anyhow::{Context as _, Result};
use ash::vk;

use super::context::Context;
use super::error::Error;
use super::guard::{Destroy, Guard};

pub struct Profiler {
    pub timestamps: vk::QueryPool,
    pub stats: Option<vk::QueryPool>,
    /// Samples that passed the depth and stencil tests (precise occlusion
    /// queries): exact on every driver, unlike invocation counters, which some
    /// drivers (llvmpipe) take before the early tests.
    pub occlusion: vk::QueryPool,
    precise: bool,
    pub max_passes: u32,
    period_ns: f64,
    valid_mask: u64,
}

/// What the GPU measured for one pass (by its query slot) in one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassTiming {
    pub barrier_ms: f64,
    pub gpu_ms: f64,
    /// Primitives the input assembler read (a draw's triangles: what
    /// shadow-caster culling and levels of detail save, counted).
    pub input_primitives: Option<u64>,
    pub fragment_invocations: Option<u64>,
    /// Compute-shader invocations (the compute path's proof that only the
    /// listed tiles ran, as the fragment count is the stencil's).
    pub compute_invocations: Option<u64>,
    pub samples_passed: u64,
}

impl Profiler {
    pub fn new(ctx: &Context, max_passes: u32) -> Result<Self> {
        if ctx.facts.timestamp_valid_bits == 0 {
            anyhow::bail!(
                "device '{}' has no timestamps on its graphics queue",
                ctx.facts.name
            );
        }
        let pool = |name: &str, info: vk::QueryPoolCreateInfo| -> Result<vk::QueryPool> {
            ctx.creation_step(&format!("query pool '{name}'"))?;
            let p = unsafe { ctx.device.create_query_pool(&info, None) }
                .map_err(Error::from)
                .with_context(|| format!("creating query pool '{name}'"))?;
            ctx.name(p, name);
            Ok(p)
        };
        // Each pool is guarded until the profiler holds them all.
        let timestamps = Guard::new(
            ctx,
            pool(
                "pass timestamps",
                vk::QueryPoolCreateInfo::default()
                    .query_type(vk::QueryType::TIMESTAMP)
                    .query_count(max_passes * 3),
            )?,
        );
        let stats = Guard::new(
            ctx,
            ctx.facts
                .pipeline_statistics
                .then(|| {
                    pool(
                        "pass shader invocations",
                        vk::QueryPoolCreateInfo::default()
                            .query_type(vk::QueryType::PIPELINE_STATISTICS)
                            // Results come in the flags' bit order: input
                            // primitives, fragment, then compute.
                            .pipeline_statistics(
                                vk::QueryPipelineStatisticFlags::INPUT_ASSEMBLY_PRIMITIVES
                                    | vk::QueryPipelineStatisticFlags::FRAGMENT_SHADER_INVOCATIONS
                                    | vk::QueryPipelineStatisticFlags::COMPUTE_SHADER_INVOCATIONS,
                            )
                            .query_count(max_passes),
                    )
                })
                .transpose()?,
        );
        let occlusion = pool(
            "pass samples passed",
            vk::QueryPoolCreateInfo::default()
                .query_type(vk::QueryType::OCCLUSION)
                .query_count(max_passes),
        )?;
        let bits = ctx.facts.timestamp_valid_bits;
        Ok(Profiler {
            timestamps: timestamps.keep(),
            stats: stats.keep(),
            occlusion,
            precise: ctx.facts.occlusion_query_precise,
            max_passes,
            period_ns: ctx.facts.timestamp_period_ns,
            valid_mask: if bits >= 64 {
                u64::MAX
            } else {
                (1u64 << bits) - 1
            },
        })
    }

    pub fn reset(&self, ctx: &Context, cmd: vk::CommandBuffer) {
        unsafe {
            ctx.device
                .cmd_reset_query_pool(cmd, self.timestamps, 0, self.max_passes * 3);
            if let Some(s) = self.stats {
                ctx.device.cmd_reset_query_pool(cmd, s, 0, self.max_passes);
            }
            ctx.device
                .cmd_reset_query_pool(cmd, self.occlusion, 0, self.max_passes);
        }
    }

    /// Timestamp `slot` (0 = before barriers, 1 = pass start, 2 = pass end) of pass `i`.
    pub fn stamp(&self, ctx: &Context, cmd: vk::CommandBuffer, i: u32, slot: u32) {
        // ALL_COMMANDS here is a timestamp stage, not a barrier: the value is written
        // once every earlier command has finished, which is what a pass boundary means.
        unsafe {
            ctx.device.cmd_write_timestamp2(
                cmd,
                vk::PipelineStageFlags2::ALL_COMMANDS,
                self.timestamps,
                i * 3 + slot,
            )
        };
    }

    pub fn begin_stats(&self, ctx: &Context, cmd: vk::CommandBuffer, i: u32) {
        unsafe {
            if let Some(s) = self.stats {
                ctx.device
                    .cmd_begin_query(cmd, s, i, vk::QueryControlFlags::empty());
            }
            let flags = if self.precise {
                vk::QueryControlFlags::PRECISE
            } else {
                vk::QueryControlFlags::empty()
            };
            ctx.device.cmd_begin_query(cmd, self.occlusion, i, flags);
        }
    }

    pub fn end_stats(&self, ctx: &Context, cmd: vk::CommandBuffer, i: u32) {
        unsafe {
            ctx.device.cmd_end_query(cmd, self.occlusion, i);
            if let Some(s) = self.stats {
                ctx.device.cmd_end_query(cmd, s, i);
            }
        }
    }

    /// Reads the results of the first `n` query slots after the frame's fence.
    pub fn read(&self, ctx: &Context, n: usize) -> Result<Vec<PassTiming>> {
        let n = n as u32;
        let mut ts = vec![0u64; (n * 3) as usize];
        unsafe {
            ctx.device.get_query_pool_results(
                self.timestamps,
                0,
                &mut ts,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }
        .map_err(Error::from)
        .context("reading timestamps")?;
        // One query's three statistics per element (ash strides by the element).
        let mut inv = vec![[0u64; 3]; n as usize];
        if let Some(s) = self.stats {
            unsafe {
                ctx.device.get_query_pool_results(
                    s,
                    0,
                    &mut inv,
                    vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
                )
            }
            .map_err(Error::from)
            .context("reading pipeline statistics")?;
        }
        let mut occ = vec![0u64; n as usize];
        unsafe {
            ctx.device.get_query_pool_results(
                self.occlusion,
                0,
                &mut occ,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }
        .map_err(Error::from)
        .context("reading occlusion queries")?;
        let ms = |a: u64, b: u64| {
            let d = (b & self.valid_mask).wrapping_sub(a & self.valid_mask) & self.valid_mask;
            d as f64 * self.period_ns * 1e-6
        };
        Ok((0..n as usize)
            .map(|i| PassTiming {
                barrier_ms: ms(ts[i * 3], ts[i * 3 + 1]),
                gpu_ms: ms(ts[i * 3 + 1], ts[i * 3 + 2]),
                input_primitives: self.stats.map(|_| inv[i][0]),
                fragment_invocations: self.stats.map(|_| inv[i][1]),
                compute_invocations: self.stats.map(|_| inv[i][2]),
                samples_passed: occ[i],
            })
            .collect())
    }

    pub fn destroy(&self, ctx: &Context) {
        unsafe {
            ctx.device.destroy_query_pool(self.timestamps, None);
            if let Some(s) = self.stats {
                ctx.device.destroy_query_pool(s, None);
            }
            ctx.device.destroy_query_pool(self.occlusion, None);
        }
    }
}

impl Destroy for Profiler {
    fn destroy(&mut self, ctx: &Context) {
        Profiler::destroy(self, ctx);
        self.timestamps = vk::QueryPool::null();
        self.stats = None;
        self.occlusion = vk::QueryPool::null();
    }
}
