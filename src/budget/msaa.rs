//! MSAA colour and Z compression (`profile::MsaaCompression`): which samples
//! of a multisampled pass are stored, resolved and pushed through the ROPs one
//! by one.
//!
//! MSAA shades once per pixel and triangle, so the samples of a pixel that one
//! fragment covers whole hold one colour and one depth plane; lossless
//! compression stores them as one. Where a triangle edge crosses a pixel its
//! samples come from two or more fragments, and the pixel is stored whole
//! ("the lossless compression techniques are only optimal when there are no
//! triangle edges intersecting a pixel", beyond3d.com/content/articles/4/4).
//! The pass's counts say how many such pixels there are: each pixel whose
//! samples passed counts `msaa` samples, and each fragment one, so the
//! fragments beyond the covered pixels are the second fragments of partly
//! covered pixels ([`Coverage::of`]). That holds where fragments are counted
//! after the early tests (NVIDIA's invocation counts; `record::FRAGMENTS_RULE`);
//! where they are not, the frame has no partly covered pixel and
//! compression is a lower bound of the cost.
//!
//! Pure arithmetic; `units` turns it into times and bytes.

use crate::budget::profile::MsaaCompression;

/// The pixels of a multisampled pass, by how their samples are covered.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coverage {
    /// Pixels' worth of samples that passed: `samples_passed / msaa`.
    pub covered: f64,
    /// Of them, pixels whose samples come from two or more fragments (a
    /// triangle edge crosses them): stored and resolved sample by sample.
    pub partial: f64,
}

impl Coverage {
    /// From a pass's shaded fragments and samples passed at `msaa` samples
    /// per pixel: every fragment beyond one per covered pixel is the second
    /// fragment of a partly covered pixel (a pixel three fragments share
    /// counts twice, as its two extra fragments; clamped to the covered pixels).
    pub fn of(fragments: f64, samples_passed: f64, msaa: u32) -> Coverage {
        let covered = samples_passed / f64::from(msaa.max(1));
        let partial = (fragments - covered).clamp(0.0, covered);
        Coverage { covered, partial }
    }

    /// Pixels one fragment covers whole.
    pub fn whole(&self) -> f64 {
        self.covered - self.partial
    }

    /// The share of the covered pixels that are partly covered (0 when
    /// nothing is covered).
    pub fn partial_share(&self) -> f64 {
        if self.covered > 0.0 {
            self.partial / self.covered
        } else {
            0.0
        }
    }
}

/// Samples stored (written to memory, and read back by a resolve) per covered
/// pixel at `msaa` samples: all of them without compression; one for a whole
/// pixel and `msaa` for a partly covered one with it.
pub fn stored_samples_per_pixel(partial_share: f64, msaa: u32, c: MsaaCompression) -> f64 {
    let n = f64::from(msaa.max(1));
    match c {
        MsaaCompression::None => n,
        MsaaCompression::Storage | MsaaCompression::StorageAndRop => {
            1.0 + partial_share.clamp(0.0, 1.0) * (n - 1.0)
        }
    }
}

/// Samples a colour target of a pass of `n` fragments stores (and its resolve
/// reads back): `msaa` per fragment without compression, else per covered
/// pixel as [`stored_samples_per_pixel`] says.
pub fn colour_samples(n: f64, cov: &Coverage, msaa: u32, c: MsaaCompression) -> f64 {
    match c {
        MsaaCompression::None => n * f64::from(msaa.max(1)),
        c => cov.covered * stored_samples_per_pixel(cov.partial_share(), msaa, c),
    }
}

/// Depth/stencil samples a pass of `n` fragments and `passed` samples passed
/// touches. The occlusion query counts samples and the fragments count
/// pixels, so without compression the larger of `n x msaa` and `passed`;
/// with it, the pixels touched (the covered ones, or the fragments, a partly
/// covered pixel's second aside, where more were tested than passed) times
/// the samples each stores.
pub fn depth_samples(n: f64, passed: f64, msaa: u32, c: MsaaCompression) -> f64 {
    match c {
        MsaaCompression::None => (n * f64::from(msaa.max(1))).max(passed),
        c => {
            let cov = Coverage::of(n, passed, msaa);
            let per_px = stored_samples_per_pixel(cov.partial_share(), msaa, c);
            cov.covered.max(n - cov.partial) * per_px
        }
    }
}

/// Texels a load-op clear of a `pixels`-pixel target writes: every sample,
/// or one value per pixel for a compressed target (it is cleared in its
/// compressed form).
pub fn cleared_texels(pixels: f64, msaa: u32, c: MsaaCompression) -> f64 {
    match c {
        MsaaCompression::None => pixels * f64::from(msaa.max(1)),
        _ => pixels,
    }
}

/// Seconds the ROPs take for one colour target of a multisampled pass under
/// compression `c` (`Storage` or `StorageAndRop`; `None` keeps `units`' own
/// rule): a whole pixel takes a pixel slot (`pixel_rate`, pixels/s) or, where
/// compression does not reach the ROPs, its `msaa` samples at `sample_rate`
/// (samples/s), whichever is longer; a partly covered pixel takes its two
/// fragments' slots or its `msaa` samples at `sample_rate`.
pub fn rop_seconds(
    cov: &Coverage,
    msaa: u32,
    c: MsaaCompression,
    pixel_rate: f64,
    sample_rate: f64,
) -> f64 {
    let n = f64::from(msaa.max(1));
    let samples = n / sample_rate;
    let whole = match c {
        MsaaCompression::StorageAndRop => 1.0 / pixel_rate,
        MsaaCompression::Storage | MsaaCompression::None => samples.max(1.0 / pixel_rate),
    };
    let partial = samples.max(2.0 / pixel_rate);
    cov.whole() * whole + cov.partial * partial
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coverage_counts_the_fragments_beyond_one_per_pixel() {
        // 1000 pixels at 4x: 900 covered by one fragment, 100 shared by two.
        let c = Coverage::of(1100.0, 4000.0, 4);
        assert_eq!(c.covered, 1000.0);
        assert_eq!(c.partial, 100.0);
        assert_eq!(c.whole(), 900.0);
        assert!((c.partial_share() - 0.1).abs() < 1e-12);
        // At 1x every fragment is its pixel: nothing is partial.
        assert_eq!(Coverage::of(500.0, 500.0, 1).partial, 0.0);
        // Counts taken before the early tests can be below the samples' pixels:
        // no partial pixel, never a negative one; nor more partial than covered.
        assert_eq!(Coverage::of(900.0, 4000.0, 4).partial, 0.0);
        assert_eq!(Coverage::of(5000.0, 4000.0, 4).partial, 1000.0);
        assert_eq!(Coverage::of(0.0, 0.0, 4).partial_share(), 0.0);
    }

    #[test]
    fn compression_stores_one_sample_per_whole_pixel() {
        use MsaaCompression::*;
        for n in [2, 4, 8] {
            let nf = f64::from(n);
            assert_eq!(stored_samples_per_pixel(0.3, n, None), nf);
            for c in [Storage, StorageAndRop] {
                // Bounds: one sample per pixel with no edge, all of them with
                // edges everywhere; linear in between.
                assert_eq!(stored_samples_per_pixel(0.0, n, c), 1.0);
                assert_eq!(stored_samples_per_pixel(1.0, n, c), nf);
                let s = stored_samples_per_pixel(0.25, n, c);
                assert!((s - (0.75 + 0.25 * nf)).abs() < 1e-12, "{s}");
            }
        }
        assert_eq!(stored_samples_per_pixel(0.5, 1, Storage), 1.0);
    }

    #[test]
    fn depth_and_colour_samples_count_each_sample_once() {
        use MsaaCompression::*;
        // 1000 pixels at 4x, 100 of them shared by two fragments.
        let cov = Coverage::of(1100.0, 4000.0, 4);
        // Without compression: a sample per fragment and sample; the
        // occlusion query's samples are not multiplied again.
        assert_eq!(depth_samples(1100.0, 4000.0, 4, None), 4400.0);
        assert_eq!(depth_samples(1000.0, 4000.0, 4, None), 4000.0);
        assert_eq!(colour_samples(1100.0, &cov, 4, None), 4400.0);
        // Compressed: 900 whole pixels once, 100 partial ones four times.
        for c in [Storage, StorageAndRop] {
            assert_eq!(colour_samples(1100.0, &cov, 4, c), 1300.0);
            assert_eq!(depth_samples(1100.0, 4000.0, 4, c), 1300.0);
            assert_eq!(cleared_texels(1000.0, 4, c), 1000.0);
        }
        assert_eq!(cleared_texels(1000.0, 4, None), 4000.0);
        // At 1x all rules agree with a pixel per fragment.
        let one = Coverage::of(500.0, 500.0, 1);
        for c in [None, Storage, StorageAndRop] {
            assert_eq!(colour_samples(500.0, &one, 1, c), 500.0);
            assert_eq!(depth_samples(500.0, 500.0, 1, c), 500.0);
        }
    }

    #[test]
    fn rop_time_is_the_per_sample_rate_times_the_samples_it_processes() {
        use MsaaCompression::*;
        // G92-like: 11.8 Gpix/s, 47.2 Gsamples/s (4 samples a pixel clock).
        let (px, sm) = (11.8e9, 47.2e9);
        let all_whole = Coverage {
            covered: 1e6,
            partial: 0.0,
        };
        // 4x: the sample rate covers a pixel's four samples in one slot.
        let t4 = rop_seconds(&all_whole, 4, Storage, px, sm);
        assert!((t4 - 1e6 / px).abs() < 1e-15, "{t4}");
        // 8x on storage-only compression: every sample at the sample rate,
        // half the pixel rate.
        let t8 = rop_seconds(&all_whole, 8, Storage, px, sm);
        assert!((t8 - 8e6 / sm).abs() < 1e-15 && (t8 / t4 - 2.0).abs() < 1e-9);
        // With ROP compression whole pixels take one pixel slot at any count.
        let r8 = rop_seconds(&all_whole, 8, StorageAndRop, px, sm);
        assert!((r8 - 1e6 / px).abs() < 1e-15);
        // GF100-like (24.3 Gpix/s, 24.3 Gsamples/s uncompressed): a partly
        // covered pixel's eight samples take eight sample slots.
        let p = Coverage {
            covered: 1e6,
            partial: 1e5,
        };
        let g = rop_seconds(&p, 8, StorageAndRop, 24.3e9, 24.3e9);
        let want = 9e5 / 24.3e9 + 1e5 * 8.0 / 24.3e9;
        assert!((g - want).abs() < 1e-15, "{g} {want}");
        // More partial pixels never cost less (equal where a partly covered
        // pixel's two slots take as long as its samples: G92 at 8x).
        let more = Coverage {
            covered: 1e6,
            partial: 2e5,
        };
        for c in [Storage, StorageAndRop] {
            for n in [2, 4, 8] {
                let (a, b) = (
                    rop_seconds(&more, n, c, px, sm),
                    rop_seconds(&p, n, c, px, sm),
                );
                assert!(a >= b * (1.0 - 1e-12), "{c:?} {n}x: {a} < {b}");
            }
        }
    }
}
