//! How the ground truth splits its surface samples so that every binding and
//! every image stays within the device's limits (pure: the limits come in as
//! numbers; `method::reference` reads them off the device), and the bound of
//! one gather invocation's work in one slab.

use anyhow::{bail, Result};

use super::sampling::{Grid, SurfaceSample};

/// Width of the radiance images: sample i of a chunk is texel (i % width, i / width).
pub const RADIANCE_WIDTH: u32 = 2048;

/// The device limits the split follows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChunkLimits {
    /// maxStorageBufferRange, bytes.
    pub storage_range: u64,
    /// maxImageDimension2D.
    pub max_image_dimension: u32,
}

/// How the samples are split.
#[derive(Clone, Debug, PartialEq)]
pub struct ChunkPlan {
    /// (first sample, count) of each gather chunk: positions bound whole,
    /// radiance image of `count.div_ceil(RADIANCE_WIDTH)` rows.
    pub chunks: Vec<(u32, u32)>,
    /// Samples per draw of the radiance pass (its 64-byte samples bound by range).
    pub draw_samples: u32,
}

/// Splits `count` samples into chunks of whole radiance rows within `limits`.
pub fn plan_chunks(count: u32, limits: ChunkLimits) -> Result<ChunkPlan> {
    let sample_bytes = std::mem::size_of::<SurfaceSample>() as u64;
    let rows_by =
        |bytes_per_sample: u64| limits.storage_range / (bytes_per_sample * RADIANCE_WIDTH as u64);
    // Positions are vec4 (16 bytes) read by the gather; samples 64 bytes read
    // by the radiance pass, one range per draw.
    let chunk_rows = rows_by(16).min(limits.max_image_dimension as u64);
    let draw_rows = rows_by(sample_bytes);
    if chunk_rows == 0 || draw_rows == 0 {
        bail!(
            "this device's storage-buffer range ({} bytes) cannot hold one row of {RADIANCE_WIDTH} reference samples",
            limits.storage_range
        );
    }
    let per_chunk = (chunk_rows * RADIANCE_WIDTH as u64).min(u32::MAX as u64) as u32;
    let mut chunks = Vec::new();
    let mut first = 0u32;
    while first < count {
        let n = (count - first).min(per_chunk);
        chunks.push((first, n));
        first += n;
    }
    Ok(ChunkPlan {
        chunks,
        draw_samples: (draw_rows * RADIANCE_WIDTH as u64).min(u32::MAX as u64) as u32,
    })
}

/// The most samples one gather invocation visits in one slab: the largest sum of
/// the counts of a row of 3 neighbouring cells (an upper bound of its radiance
/// fetches, which are the visited samples within the cut-off).
pub fn max_slab_candidates(grid: &Grid) -> u32 {
    let [nx, ny, nz] = grid.dims.map(|d| d as i64);
    let count = |x: i64, y: i64, z: i64| -> u32 {
        if x < 0 || y < 0 || z < 0 || x >= nx || y >= ny || z >= nz {
            return 0;
        }
        let i = ((z * ny + y) * nx + x) as usize;
        grid.cell_start[i + 1] - grid.cell_start[i]
    };
    let mut best = 0;
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                best = best.max(count(x - 1, y, z) + count(x, y, z) + count(x + 1, y, z));
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    // lavapipe: 128 MiB of storage range, 16384-texel images. The Lee
    // Perry-Smith bust at 32 samples per mm^2 is 10.9 M samples.
    #[test]
    fn chunks_stay_within_the_limits_and_cover_every_sample() {
        let lavapipe = ChunkLimits {
            storage_range: 134_217_728,
            max_image_dimension: 16384,
        };
        let plan = plan_chunks(10_885_671, lavapipe).unwrap();
        assert_eq!(plan.chunks.len(), 2);
        let mut next = 0;
        for &(first, n) in &plan.chunks {
            assert_eq!(first, next);
            assert!(n as u64 * 16 <= lavapipe.storage_range);
            assert!(n.div_ceil(RADIANCE_WIDTH) <= lavapipe.max_image_dimension);
            assert_eq!(first % RADIANCE_WIDTH, 0, "chunks start on whole rows");
            next = first + n;
        }
        assert_eq!(next, 10_885_671);
        assert!(plan.draw_samples as u64 * 64 <= lavapipe.storage_range);
        // A small image limit splits by rows instead.
        let small = ChunkLimits {
            storage_range: 1 << 40,
            max_image_dimension: 4096,
        };
        let plan = plan_chunks(10_885_671, small).unwrap();
        assert_eq!(plan.chunks[0].1, 4096 * RADIANCE_WIDTH);
        // Below one row of range: a clear error.
        let tiny = ChunkLimits {
            storage_range: 1024,
            max_image_dimension: 4096,
        };
        assert!(plan_chunks(10, tiny).is_err());
        assert!(plan_chunks(0, lavapipe).unwrap().chunks.is_empty());
    }

    #[test]
    fn slab_candidates_bound_the_visited_samples() {
        let grid = Grid {
            origin: glam::Vec3::ZERO,
            cell: 1.0,
            dims: [3, 1, 1],
            cell_start: vec![0, 5, 6, 10],
        };
        assert_eq!(max_slab_candidates(&grid), 10);
    }
}
