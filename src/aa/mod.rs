//! Anti-aliasing's device-free core (issue 17, part 1): the lookup tables and
//! CPU references of Jimenez's MLAA (thesis ch. 9) and SMAA (ch. 10), plain
//! Rust that the GPU passes will upload and be checked against.
//!
//! - `revector`: the orthogonal re-vectorisation both share: crossing edges,
//!   the 16 patterns, the exact areas of L, Z and U shapes (ch. 9.2, 10.4.2).
//! - `mlaa_area`: MLAA's 45 x 45 area texture, 5 x 5 subtextures of 9 x 9
//!   (ch. 9.4.3, Listing 9.4).
//! - `mlaa_weights`: the CPU mirror of MLAA's blending-weight pass (ch. 9.4).
//! - `smaa_area`, `smaa_diag`: SMAA's 160 x 560 area texture, orthogonal
//!   (quadratically compressed distances, 7 subpixel offsets) and diagonal
//!   (5 offsets) halves, as `SMAA.hlsl` addresses it; R8G8 bytes, generated
//!   once per process.
//! - `smaa_search`: SMAA's 64 x 16 search texture, the decoding of the
//!   searches' last bilinear fetch (ch. 10.4.2, Eq. 10.5).
//! - `edges`: MLAA luma and depth edges, SMAA luma and colour edges with local
//!   contrast adaptation (ch. 9.3, 10.4.1, Eq. 10.1).
//!
//! Orientation: every table and image here is stored row 0 first and read
//! with `v = 0` at row 0, rows running top to bottom as Vulkan stores,
//! samples and rasterises them (NDC y down, positive viewport height). That is
//! D3D's convention, which SMAA's tables were made for, so no flip is needed
//! (`smaa_area` tests it on a staircase). docs/aa.md says what each function
//! computes and what the GPU passes still need.
pub mod edges;
pub mod mlaa_area;
pub mod mlaa_weights;
pub mod revector;
pub mod smaa_area;
pub mod smaa_diag;
pub mod smaa_search;

#[cfg(test)]
mod tests {
    use std::time::{Duration, Instant};

    /// Each table is a pure function of the chapters' definitions: two
    /// generations give the same bytes (what the per-process cache relies
    /// on). Their times are printed, not asserted (speed is a benchmark's
    /// business, not a timed test's): `--nocapture` shows the times
    /// docs/aa.md quotes, the best of five so a busy machine inflates less.
    #[test]
    fn tables_generate_the_same_bytes_every_time() {
        fn best<T: PartialEq + std::fmt::Debug>(f: impl Fn() -> T) -> Duration {
            let first = f();
            (0..5)
                .map(|_| {
                    let t0 = Instant::now();
                    let again = std::hint::black_box(f());
                    let dt = t0.elapsed();
                    assert!(again == first, "a second generation differs");
                    dt
                })
                .min()
                .unwrap_or_default()
        }
        let times = [
            (
                "MLAA area 45x45",
                best(super::mlaa_area::MlaaAreaTex::generate),
            ),
            (
                "SMAA area 160x560",
                best(super::smaa_area::SmaaAreaTex::generate),
            ),
            (
                "SMAA search 64x16",
                best(super::smaa_search::SmaaSearchTex::generate),
            ),
        ];
        for (what, dt) in times {
            eprintln!("{what}: generated in {dt:?}");
        }
    }
}
