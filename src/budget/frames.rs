//! Frames to price besides a live run's: the stored frames of
//! `profiles/frames/` (dermis's frames of the published scenes and of the
//! benchmark configurations, rendered on lavapipe by `tools/budget_frames.sh`),
//! the pairing of a benchmark report with the stored frame of its
//! configuration, the transformations that turn a dermis frame into the
//! implementation a source timed (no seed copy, no skin on screen, twelve
//! passes), and first-principles frames of published techniques dermis does
//! not render (MLAA). Every transformation keys on roles and declared work,
//! never on a pass's label.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use crate::budget::input::{FrameInput, PassInput};
use crate::budget::record::{counting, FragmentCounting};
use crate::graph::work::{
    ColorWrite, DepthStencilUse, Fetch, Filter, Format, ImageUse, ImageUseKind, PassRole,
    ShaderWork, Work,
};
use crate::report::Report;

/// `profiles/frames/` beside Cargo.toml.
pub fn frames_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/frames")
}

/// `docs/perf/` beside Cargo.toml.
pub fn perf_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/perf")
}

/// A stored frame (a `frames/METHOD.json` of `dermis budget`), read through
/// the one door (`files`) and checked ([`check_frame`]).
pub fn load_frame(path: &Path) -> Result<FrameInput> {
    let text = crate::files::read_text(path, "stored frame", crate::files::MAX_TEXT_FILE)?;
    let f: FrameInput =
        serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))?;
    check_frame(&f).with_context(|| format!("stored frame {}", path.display()))?;
    Ok(f)
}

/// The ranges `render` holds a frame to, for a frame whoever wrote it: sizes
/// (the frame's, each render area's and image's) within 1..=`MAX_IMAGE_SIDE`,
/// 1..=64 samples a pixel (Vulkan's largest sample count), per-invocation
/// figures (fetches, ALU, storage bytes) and measured times finite and not
/// negative, and no raster pass with more fragments, samples or rasterised
/// pixels than its triangles can cover (each covers at most its render area).
pub fn check_frame(f: &FrameInput) -> Result<()> {
    let max = crate::scene::MAX_IMAGE_SIDE;
    let side = |what: &str, v: u32| -> Result<()> {
        if !(1..=max).contains(&v) {
            bail!("{what} must be within 1..={max} pixels (as render's --width/--height), got {v}");
        }
        Ok(())
    };
    let amount = |what: &str, v: f64| -> Result<()> {
        if !(v.is_finite() && v >= 0.0) {
            bail!("{what} must be a finite number, not negative, got {v}");
        }
        Ok(())
    };
    side("width", f.width)?;
    side("height", f.height)?;
    for (i, p) in f.passes.iter().enumerate() {
        let at = |what: &str| format!("pass {i} ('{}'): {what}", p.name);
        if let Some(ms) = p.measured_ms {
            amount(&at("measured_ms"), ms)?;
        }
        for im in &p.images {
            side(&at(&format!("image '{}' width", im.image)), im.width)?;
            side(&at(&format!("image '{}' height", im.image)), im.height)?;
        }
        let shader = match &p.work {
            Work::Raster { shader, .. } => shader.as_ref(),
            Work::Compute { shader, .. } => Some(shader),
            _ => None,
        };
        if let Some(s) = shader {
            amount(&at("alu"), s.alu)?;
            amount(&at("storage_read_bytes"), s.storage_read_bytes)?;
            amount(&at("storage_write_bytes"), s.storage_write_bytes)?;
            for x in &s.fetches {
                amount(&at(&format!("fetch count of '{}'", x.texture)), x.count)?;
            }
        }
        if let Work::Raster {
            width,
            height,
            triangles,
            msaa,
            ..
        } = &p.work
        {
            side(&at("render area width"), *width)?;
            side(&at("render area height"), *height)?;
            if !(1..=64).contains(msaa) {
                bail!("{} must be within 1..=64, got {msaa}", at("msaa"));
            }
            let most = (*width as u64 * *height as u64 * *msaa as u64).saturating_mul(*triangles);
            for (what, n) in [
                ("fragments", p.fragments),
                ("samples_passed", p.samples_passed),
                ("rasterized_pixels", p.rasterized_pixels.unwrap_or(0)),
            ] {
                if n > most {
                    bail!(
                        "{} is {n}, more than its {triangles} triangles can cover in {width}x{height} at {msaa} samples ({most})",
                        at(what)
                    );
                }
            }
        }
    }
    Ok(())
}

/// The `.json` files of a directory, sorted (none when it does not exist).
pub fn json_files(dir: &Path) -> Result<Vec<PathBuf>> {
    if !dir.is_dir() {
        return Ok(Vec::new());
    }
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("listing {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    Ok(files)
}

fn is_sss_draw(p: &PassInput) -> bool {
    p.role == PassRole::Sss && matches!(p.work, Work::Raster { .. })
}

/// Without the SSS seed copies (the thesis' SSSS shader blurs into its own
/// target and copies nothing).
pub fn without_seed_copies(f: &FrameInput) -> FrameInput {
    let mut g = f.clone();
    g.passes
        .retain(|p| !(p.role == PassRole::Sss && matches!(p.work, Work::Copy { .. })));
    g
}

/// No skin on screen: the SSS draws shade nothing and their stencil rejects
/// every pixel they cover (the thesis' "fixed costs").
pub fn skinless(f: &FrameInput) -> FrameInput {
    let mut g = f.clone();
    for p in g.passes.iter_mut().filter(|p| is_sss_draw(p)) {
        p.fragments = 0;
        p.samples_passed = 0;
    }
    g
}

/// Seed 001's "Gaussian sum": six Gaussians, each a horizontal and a
/// vertical pass like the separable frame's (its Figure 3.4 shader): every
/// SSS draw of `f` six times.
pub fn six_gaussians(f: &FrameInput) -> FrameInput {
    let mut g = f.clone();
    g.passes = Vec::new();
    for p in &f.passes {
        let copies = if is_sss_draw(p) { 6 } else { 1 };
        for k in 0..copies {
            let mut q = p.clone();
            if copies > 1 {
                q.name = format!("{} g{}", p.name, k + 1);
                q.measured_ms = None;
            }
            g.passes.push(q);
        }
    }
    g.label = format!("{} as six Gaussians", f.label);
    g
}

/// Every bilinear fetch count of the SSS draws times `factor` (a kernel of
/// other taps than the one rendered).
pub fn scale_taps(f: &FrameInput, factor: f64) -> FrameInput {
    let mut g = f.clone();
    for p in g.passes.iter_mut().filter(|p| is_sss_draw(p)) {
        if let Work::Raster {
            shader: Some(s), ..
        } = &mut p.work
        {
            for x in s
                .fetches
                .iter_mut()
                .filter(|x| x.filter == Filter::Bilinear)
            {
                x.count *= factor;
            }
        }
    }
    g
}

/// A benchmark report whose passes carry no declarations (docs/perf/h100/)
/// priced with the stored frame of its configuration: that frame's work,
/// images and counted fetches, with the report's own counts and times (its
/// driver's fragment counts, its samples passed, its SSS region's pixels and
/// rectangles for the region-limited draws and copies).
pub fn paired_frame(rep: &Report, stored: &FrameInput) -> Result<FrameInput> {
    let names = |v: Vec<&str>| v.join(", ");
    if rep.passes.len() != stored.passes.len()
        || rep
            .passes
            .iter()
            .zip(&stored.passes)
            .any(|(a, b)| a.name != b.name)
    {
        bail!(
            "passes differ: report [{}], frame [{}]",
            names(rep.passes.iter().map(|p| p.name.as_str()).collect()),
            names(stored.passes.iter().map(|p| p.name.as_str()).collect())
        );
    }
    let area = u64::from(rep.run.width) * u64::from(rep.run.height);
    let region = rep.sss_region_pixels.unwrap_or(area);
    let rects = rep.sss_region_rects.unwrap_or(1);
    // The stored run's region, from its region-limited draws.
    let stored_region = stored.passes.iter().find_map(|p| p.rasterized_pixels);
    let nvidia = counting(rep) == FragmentCounting::AfterEarlyTests;
    let mut g = stored.clone();
    for (q, r) in g.passes.iter_mut().zip(&rep.passes) {
        q.samples_passed = r.samples_passed;
        q.measured_ms = Some(r.gpu_ms.median);
        let shades = matches!(
            q.work,
            Work::Raster {
                shader: Some(_),
                ..
            }
        );
        if shades {
            q.fragments = match r.fragment_invocations {
                Some(n) if nvidia => n,
                _ => r.samples_passed,
            };
        }
        if q.rasterized_pixels.is_some() {
            q.rasterized_pixels = Some(region);
            if let Work::Raster { triangles, .. } = &mut q.work {
                *triangles = rects;
            }
        }
        if let (
            Work::Copy {
                texels, rects: r2, ..
            },
            Some(sr),
        ) = (&mut q.work, stored_region)
        {
            if sr > 0 && *texels % sr == 0 && (1..=4).contains(&(*texels / sr)) {
                let k = *texels / sr;
                *texels = k * region;
                *r2 = (k * rects) as u32;
            }
        }
    }
    g.provenance.push(format!(
        "counts and times: the report of {} ({}); work, images and fetches: the stored frame",
        rep.run.device.device, rep.run.command
    ));
    Ok(g)
}

/// A new-format benchmark report (declared work in every pass) with the
/// counted fetches of the stored frame of its configuration, when there is
/// one (a bench runs no counting build).
pub fn with_counted_fetches(f: &FrameInput, stored: Option<&FrameInput>) -> FrameInput {
    let mut g = f.clone();
    let Some(s) = stored.filter(|s| {
        s.passes.len() == f.passes.len()
            && s.passes
                .iter()
                .zip(&f.passes)
                .all(|(a, b)| a.name == b.name)
    }) else {
        return g;
    };
    for (q, sp) in g.passes.iter_mut().zip(&s.passes) {
        if !sp.fetches_counted {
            continue;
        }
        let shader = |w: &Work| match w {
            Work::Raster {
                shader: Some(sh), ..
            } => Some(sh.fetches.clone()),
            Work::Compute { shader, .. } => Some(shader.fetches.clone()),
            _ => None,
        };
        let counted = shader(&sp.work);
        match (&mut q.work, counted) {
            (
                Work::Raster {
                    shader: Some(sh), ..
                },
                Some(c),
            ) if c.len() == sh.fetches.len() => sh.fetches = c,
            (Work::Compute { shader: sh, .. }, Some(c)) if c.len() == sh.fetches.len() => {
                sh.fetches = c;
                // A report from before `shared_bytes` was declared (0 then):
                // the stored frame's declaration of the same shader has it.
                if let Work::Compute { shader: st, .. } = &sp.work {
                    if sh.shared_bytes == 0.0 && st.shader == sh.shader {
                        sh.shared_bytes = st.shared_bytes;
                    }
                }
            }
            _ => continue,
        }
        q.fetches_counted = true;
    }
    g.provenance
        .push("fetches: counted on lavapipe in the stored frame of this configuration".into());
    g
}

fn img(name: &str, format: Format, w: u32, h: u32, kind: ImageUseKind) -> ImageUse {
    ImageUse {
        image: name.to_string(),
        format,
        width: w,
        height: h,
        kind,
    }
}

fn fetch(texture: &str, format: Format, filter: Filter, count: f64) -> Fetch {
    Fetch {
        texture: texture.to_string(),
        format,
        filter,
        count,
        exact: true,
        coherent: true,
        spread: Vec::new(),
    }
}

/// The most bilinear search fetches MLAA's weights pass makes per edge pixel:
/// two edgels, two searches each, each reaching the Xbox 360's `tfetch2D`
/// offset of 8 pixels (`aa::mlaa_area::XBOX360_TFETCH2D_MIN_OFFSET_PX`, ch.
/// 9.4.1) at two pixels per fetch: 16. `mlaa_frame` charges at most this.
pub const MLAA_MAX_SEARCH_TAPS: f64 =
    (2 * 2 * (-crate::aa::mlaa_area::XBOX360_TFETCH2D_MIN_OFFSET_PX / 2)) as f64;

// The port's searches (`post::mlaa`'s declared bound) reach as far.
const _: () = assert!(
    4 * crate::shader_constants::MLAA_MAX_SEARCH_STEPS as i32 == MLAA_MAX_SEARCH_TAPS as i32
);

/// One MLAA draw: `shader` into an RGBA8 target, with `ds`, clearing `clears`.
fn mlaa_draw(w: u32, h: u32, shader: ShaderWork, ds: DepthStencilUse, clears: Vec<Format>) -> Work {
    Work::Raster {
        shader: Some(shader),
        color: vec![ColorWrite {
            format: Format::Rgba8Unorm,
            blend: false,
        }],
        depth_stencil: Some(ds),
        width: w,
        height: h,
        triangles: 2,
        msaa: 1,
        clears,
    }
}

/// Jimenez's MLAA (thesis 000 ch. 9) at `w` x `h` from first principles: edge
/// detection on every pixel (5 point fetches of the colour, luminance
/// variant), then blending weights and neighbourhood blending on edge pixels
/// only (stencil). `edge_share` of the pixels are edges (an assumption: the
/// thesis gives no count); the weights pass searches `search_taps` bilinear
/// taps on average (its loops stop at the edge's end) plus 2 area-texture and
/// 1 edge fetch; blending makes 3 point and 4 bilinear fetches. The search
/// taps are capped at [`MLAA_MAX_SEARCH_TAPS`] (the Xbox 360's reach), and
/// the edges target has the Xbox 360's four channels
/// (`aa::mlaa_area::XBOX360_EDGES_TARGET_CHANNELS`: RGBA8).
pub fn mlaa_frame(w: u32, h: u32, edge_share: f64, search_taps: f64) -> FrameInput {
    let search_taps = search_taps.clamp(0.0, MLAA_MAX_SEARCH_TAPS);
    let px = u64::from(w) * u64::from(h);
    let edges = (px as f64 * edge_share).round() as u64;
    let d24 = Format::D24UnormS8Uint;
    let write = DepthStencilUse {
        format: d24,
        depth_test: false,
        depth_write: false,
        stencil_test: false,
        stencil_write: true,
    };
    let test = DepthStencilUse {
        stencil_test: true,
        stencil_write: false,
        ..write
    };
    let sw = |fetches, alu| ShaderWork {
        fetches,
        alu,
        ..Default::default()
    };
    let rgba8 = Format::Rgba8Unorm;
    let mut detect = PassInput::new(
        "mlaa edge detection",
        PassRole::Post,
        mlaa_draw(
            w,
            h,
            sw(vec![fetch("colorTex", rgba8, Filter::Point, 5.0)], 25.0),
            write,
            vec![rgba8, d24],
        ),
    );
    // Every pixel runs the shader; only edges are written (the rest discard).
    detect.fragments = px;
    detect.samples_passed = edges;
    detect.images = vec![
        img("color", rgba8, w, h, ImageUseKind::Sampled),
        img("edges", rgba8, w, h, ImageUseKind::ColorTarget),
        img("stencil", d24, w, h, ImageUseKind::DepthTarget),
    ];
    let weights_shader = sw(
        vec![
            fetch("edgesTex", rgba8, Filter::Point, 1.0),
            fetch("edgesTex", rgba8, Filter::Bilinear, search_taps),
            fetch("areaTex", rgba8, Filter::Point, 2.0),
        ],
        20.0 + 4.0 * search_taps,
    );
    let mut weights = PassInput::new(
        "mlaa blending weights",
        PassRole::Post,
        mlaa_draw(w, h, weights_shader, test, vec![rgba8]),
    );
    weights.images = vec![
        img("edges", rgba8, w, h, ImageUseKind::Sampled),
        img("weights", rgba8, w, h, ImageUseKind::ColorTarget),
        img("stencil", d24, w, h, ImageUseKind::DepthTest),
    ];
    let blend_shader = sw(
        vec![
            fetch("blendTex", rgba8, Filter::Point, 3.0),
            fetch("colorTex", rgba8, Filter::Bilinear, 4.0),
        ],
        20.0,
    );
    let mut blend = PassInput::new(
        "mlaa neighbourhood blending",
        PassRole::Post,
        mlaa_draw(w, h, blend_shader, test, vec![]),
    );
    blend.images = vec![
        img("weights", rgba8, w, h, ImageUseKind::Sampled),
        img("color", rgba8, w, h, ImageUseKind::Sampled),
        img("output", rgba8, w, h, ImageUseKind::ColorTargetLoad),
        img("stencil", d24, w, h, ImageUseKind::DepthTest),
        img("output", rgba8, w, h, ImageUseKind::Host),
    ];
    for p in [&mut weights, &mut blend] {
        p.fragments = edges;
        p.samples_passed = edges;
        p.rasterized_pixels = Some(px);
    }
    FrameInput {
        label: format!("MLAA {w}x{h}, {:.0}% edge pixels", edge_share * 100.0),
        width: w,
        height: h,
        passes: vec![detect, weights, blend],
        provenance: vec!["first principles (frames::mlaa_frame)".into()],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stored(dir: &str, name: &str) -> FrameInput {
        load_frame(&frames_dir().join(dir).join(format!("{name}.json"))).unwrap()
    }

    #[test]
    fn stored_frames_load_with_counted_fetches() {
        let f = stored("published", "t62_separable_close");
        assert_eq!((f.width, f.height), (1920, 1080));
        assert!(f.passes.iter().any(|p| p.fetches_counted));
        let g = without_seed_copies(&f);
        assert_eq!(g.passes.len(), f.passes.len() - 1);
        let s = skinless(&f);
        assert!(s
            .passes
            .iter()
            .filter(|p| is_sss_draw(p))
            .all(|p| p.fragments == 0 && p.rasterized_pixels == Some(1920 * 1080)));
        let six = six_gaussians(&f);
        assert_eq!(six.passes.len(), f.passes.len() + 10);
    }

    // Ch. 9.4.1's Xbox 360 facts as the first-principles frame uses them: no
    // more search taps than the tfetch2D reach allows, whatever the caller
    // asks, and a four-channel (one byte each) edges target.
    #[test]
    fn mlaa_frames_search_no_further_than_the_xbox_360_reaches() {
        assert_eq!(MLAA_MAX_SEARCH_TAPS, 16.0);
        for (asked, charged) in [(8.0, 8.0), (40.0, MLAA_MAX_SEARCH_TAPS)] {
            let f = mlaa_frame(1280, 720, 0.1, asked);
            let Work::Raster {
                shader: Some(s), ..
            } = &f.passes[1].work
            else {
                panic!("the weights pass is a draw")
            };
            let taps: f64 = s
                .fetches
                .iter()
                .filter(|f| f.filter == Filter::Bilinear)
                .map(|f| f.count)
                .sum();
            assert_eq!(taps, charged, "asked {asked}");
        }
        let f = mlaa_frame(1280, 720, 0.1, 8.0);
        let edges = f.passes[0].images.iter().find(|i| i.image == "edges");
        assert_eq!(
            edges.map(|e| e.format.bytes_per_texel() as usize),
            Some(crate::aa::mlaa_area::XBOX360_EDGES_TARGET_CHANNELS)
        );
    }

    #[test]
    fn an_old_report_pairs_with_its_stored_frame() {
        let name = "separable_1920x1080_near_1h";
        let rep = crate::report::load(&perf_dir().join(format!("h100/{name}.json"))).unwrap();
        let f = paired_frame(&rep, &stored("h100", name)).unwrap();
        let h = &f.passes[3];
        assert_eq!(h.fragments, 1_145_416);
        assert_eq!(h.rasterized_pixels, Some(1_414_656));
        assert!(matches!(h.work, Work::Raster { triangles: 2, .. }));
        assert!(matches!(
            f.passes[2].work,
            Work::Copy {
                texels: 1_414_656,
                rects: 2,
                ..
            }
        ));
        assert!(f.passes.iter().all(|p| p.measured_ms.is_some()));
        // Another configuration's frame does not pair.
        assert!(paired_frame(&rep, &stored("h100", "ssg_lod_1920x1080_near_1h")).is_err());
    }
}
