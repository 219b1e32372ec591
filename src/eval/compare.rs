//! `dermis compare` as a library call (no device): two render outputs
//! compared over the skin and per band, against an optional no-SSS output;
//! error images, the bands and compare.json written.

use std::path::Path;

use anyhow::{bail, Context as _, Result};
use serde::{Deserialize, Serialize};

use super::bands::{bands, Band, BandErrors, BandInput};
use super::metrics::{abs_error_map, false_colour, flip_ldr, relative_rmse};
use crate::header::RunHeader;
use crate::output::{read_exr, write_json, write_rgba8_png};

/// What `compare` measured: compare.json's schema (read back typed).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Comparison {
    #[serde(flatten)]
    pub run: RunHeader,
    pub test: String,
    pub reference: String,
    /// The no-SSS output err/none and the gains are relative to, if given.
    pub none: Option<String>,
    pub skin_pixels: usize,
    /// Over all skin.
    pub relative_rmse: f64,
    /// Over the whole frame.
    pub flip_mean: f64,
    /// Per band: relative RMSE, FLIP, and with a no-SSS output err/none and gain.
    pub bands: BandErrors,
}

/// A render output directory: diffuse.exr, depth.exr, frame.png, report.json.
struct Output {
    width: u32,
    height: u32,
    diffuse: Vec<[f32; 4]>,
    frame: Vec<u8>,
}

/// Refuses an image holding a NaN or infinite texel (dermis never writes
/// one: such a file is damaged or not dermis's), naming where.
fn all_finite(path: &Path, width: u32, texels: &[[f32; 4]]) -> Result<()> {
    if let Some((n, x, y)) = crate::output::first_nonfinite(texels, width) {
        bail!(
            "{}: {n} texel(s) are NaN or infinite, the first at ({x}, {y}): not an image dermis writes (damaged?)",
            path.display()
        );
    }
    Ok(())
}

impl Output {
    fn read(d: &Path) -> Result<Self> {
        let (width, height, diffuse) = read_exr(&d.join("diffuse.exr"))?;
        all_finite(&d.join("diffuse.exr"), width, &diffuse)?;
        let p = d.join("frame.png");
        // Its sides within the range `render` accepts for a frame's width and height.
        let frame_bound = crate::files::ImageBound::rgba8(crate::render::settings::MAX_IMAGE_SIDE);
        let frame = crate::files::read_rgba8(&p, "frame", &frame_bound)?.into_raw();
        Ok(Output {
            width,
            height,
            diffuse,
            frame,
        })
    }

    fn same_size(&self, other: &Output, a: &Path, b: &Path) -> Result<()> {
        if (self.width, self.height) != (other.width, other.height) {
            bail!(
                "{} is {}x{} but {} is {}x{}",
                a.display(),
                self.width,
                self.height,
                b.display(),
                other.width,
                other.height
            );
        }
        Ok(())
    }
}

/// The bands of the reference output in `b`: its skin (diffuse alpha), its
/// depth.exr and its report's field of view and scale.
fn reference_bands(b: &Path, r: &Output, mask: &[bool]) -> Result<Vec<Option<Band>>> {
    let (w, h, depth) = read_exr(&b.join("depth.exr"))?;
    if (w, h) != (r.width, r.height) {
        bail!(
            "{}: depth.exr is {w}x{h}, diffuse.exr {}x{}",
            b.display(),
            r.width,
            r.height
        );
    }
    // A depth of +inf would be compared as if it were a surface.
    all_finite(&b.join("depth.exr"), w, &depth)?;
    let report = crate::report::load(&b.join("report.json"))?;
    let depth: Vec<f32> = depth.iter().map(|d| d[0]).collect();
    Ok(bands(&BandInput::for_view(
        (w as usize, h as usize),
        mask,
        &depth,
        report.fovy_deg,
        report.mm_per_unit,
    )))
}

/// Compares the render output in `a` with the reference output in `b` (each a
/// directory with diffuse.exr, depth.exr, frame.png and report.json): relative
/// RMSE of the linear diffuse over skin pixels (skin from B), FLIP of the
/// tone-mapped frames, and both per band (interior, silhouette, depth step);
/// with `none` (the no-SSS output) also err/none and the per-channel gain per
/// band. Writes error images and compare.json into `out`.
pub fn compare(
    a: &Path,
    b: &Path,
    none: Option<&Path>,
    out: &Path,
    command: &str,
) -> Result<Comparison> {
    let (ta, rb) = (Output::read(a)?, Output::read(b)?);
    ta.same_size(&rb, a, b)?;
    let zero = none.map(Output::read).transpose()?;
    if let (Some(z), Some(n)) = (&zero, none) {
        z.same_size(&rb, n, b)?;
    }
    let (wa, ha) = (ta.width, ta.height);
    let mask: Vec<bool> = rb.diffuse.iter().map(|p| p[3] > 0.0).collect();
    let rmse = relative_rmse(&ta.diffuse, &rb.diffuse, &mask)?;
    let flip = flip_ldr(&ta.frame, &rb.frame, wa, ha)?;
    let band_of = reference_bands(b, &rb, &mask)?;
    let band_errors = BandErrors::of(
        &ta.diffuse,
        &rb.diffuse,
        zero.as_ref().map(|z| z.diffuse.as_slice()),
        &flip.error_map,
        &band_of,
    );
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let save = |name: &str, rgba: Vec<u8>| write_rgba8_png(&out.join(name), wa, ha, rgba);
    /// Relative diffuse error mapped onto the colour ramp: 0..10%.
    const DIFFUSE_RAMP_MAX: f32 = 0.1;
    save(
        "error_diffuse.png",
        false_colour(
            &abs_error_map(&ta.diffuse, &rb.diffuse, &mask),
            wa,
            ha,
            DIFFUSE_RAMP_MAX,
        ),
    )?;
    save("error_flip.png", false_colour(&flip.error_map, wa, ha, 1.0))?;
    save("bands.png", band_picture(&band_of))?;
    let c = Comparison {
        run: RunHeader::new(
            command,
            crate::header::DeviceHeader::none(),
            (wa, ha),
            (0, 0),
        ),
        test: a.display().to_string(),
        reference: b.display().to_string(),
        none: none.map(|n| n.display().to_string()),
        skin_pixels: mask.iter().filter(|&&m| m).count(),
        relative_rmse: rmse,
        flip_mean: flip.mean,
        bands: band_errors,
    };
    write_json(&out.join("compare.json"), &c)?;
    Ok(c)
}

/// The bands as a picture: interior grey, silhouette orange, depth steps blue,
/// off skin black.
fn band_picture(band_of: &[Option<Band>]) -> Vec<u8> {
    band_of
        .iter()
        .flat_map(|b| match b {
            None => [0, 0, 0, 255],
            Some(Band::Interior) => [150, 150, 150, 255],
            Some(Band::Silhouette) => [230, 159, 0, 255],
            Some(Band::DepthStep) => [0, 114, 178, 255],
        })
        .collect()
}

/// The comparison as the CLI prints it.
pub fn comparison_table(c: &Comparison) -> String {
    let mut s = format!(
        "skin pixels {}: relative RMSE {:.4e}, FLIP (frame) {:.4}\n",
        c.skin_pixels, c.relative_rmse, c.flip_mean
    );
    s.push_str(&format!(
        "{:<11} {:>8} {:>10} {:>8} {:>9} {:>17}\n",
        "band", "pixels", "rel. RMSE", "FLIP", "err/none", "gain R/G/B"
    ));
    for band in Band::ALL {
        let e = c.bands.get(band);
        let err_none = e.err_none.map_or("-".into(), |v| format!("{v:.3}"));
        let gain = e.gain.map_or("-".into(), |g| {
            format!("{:.2}/{:.2}/{:.2}", g[0], g[1], g[2])
        });
        s.push_str(&format!(
            "{:<11} {:>8} {:>10.4e} {:>8.4} {:>9} {:>17}\n",
            band.name(),
            e.pixels,
            e.rel_rmse,
            e.flip,
            err_none,
            gain
        ));
    }
    s
}
