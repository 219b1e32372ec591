//! Frames to price until the renderer hands its own (`FrameInput`s of real
//! runs): dermis's passes rebuilt from a bench report's pass names and
//! settings (the work as `src/bench/floor.rs` and the shaders declare it,
//! with the report's counts), and first-principles frames for published
//! techniques dermis does not render (MLAA, seed 001's twelve-pass sum of
//! Gaussians). Estimated quantities are named where they are set.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use serde_json::Value;

use crate::budget::input::{ClearInput, FrameInput, PassInput};
use crate::graph::work::{
    ColorWrite, DepthStencilUse, Fetch, Filter, Format, ImageUse, ImageUseKind, PassRole,
    ShaderWork, Work,
};

/// Triangles of the Lee Perry-Smith scan (`LeePerrySmith.glb`), per head.
pub const HEAD_TRIANGLES: u64 = 17_684;
/// The shadow map's size (`render::settings` default).
pub const SHADOW_SIZE: u32 = 2048;
/// Arithmetic per fragment of the geometry pass (lighting.glsl: 3x3 PCF,
/// normal mapping, Kelemen/Szirmay-Kalos, the transmittance profile): an
/// estimate by reading the shader, to be replaced by the declared count.
pub const GEOMETRY_ALU: f64 = 250.0;
/// Poisson taps per pixel: 8/16/32 by the on-screen radius, which the reports
/// do not record; 32 is the most (its pass is left out of calibration).
pub const POISSON_TAPS_ASSUMED: f64 = 32.0;

/// A frame rebuilt from one report.
#[derive(Clone, Debug)]
pub struct RunFrame {
    /// Report path relative to `docs/perf/`.
    pub file: String,
    pub method: String,
    pub heads: u32,
    pub frame: FrameInput,
}

/// Where the H100 reports live.
pub fn perf_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/perf")
}

/// How a rebuilt frame treats the SSS region.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Region {
    /// As the run did (region pixels from the report).
    AsRun,
    /// The whole screen (the thesis' implementations: full-screen quads with
    /// a stencil, copies of the whole image).
    Screen,
}

/// Knobs to rebuild a report's frame as another implementation ran it.
#[derive(Clone, Copy, Debug)]
pub struct Rebuild {
    pub region: Region,
    /// Override of the separable sample count.
    pub samples: Option<u32>,
    /// Override of follow-surface.
    pub follow_surface: Option<bool>,
    /// Leave out the separable method's seed copy (the SSSS shader of the
    /// thesis blurs into its own target and copies nothing).
    pub no_seed_copy: bool,
    /// No skin on screen: the SSS passes shade nothing, every covered pixel
    /// is rejected by the stencil (the thesis' "fixed costs").
    pub skinless: bool,
}

impl Default for Rebuild {
    fn default() -> Self {
        Rebuild {
            region: Region::AsRun,
            samples: None,
            follow_surface: None,
            no_seed_copy: false,
            skinless: false,
        }
    }
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
    }
}

fn cw(format: Format, blend: bool) -> ColorWrite {
    ColorWrite { format, blend }
}

const STENCIL_TEST: DepthStencilUse = DepthStencilUse {
    format: Format::D32FloatS8Uint,
    depth_test: false,
    depth_write: false,
    stencil_test: true,
    stencil_write: false,
};

/// A full-screen (or region) draw.
fn post_draw(
    w: u32,
    h: u32,
    shader: ShaderWork,
    color: Vec<ColorWrite>,
    stencil: bool,
    rects: u64,
) -> Work {
    Work::Raster {
        shader: Some(shader),
        color,
        depth_stencil: stencil.then_some(STENCIL_TEST),
        width: w,
        height: h,
        triangles: 2 * rects.max(1),
        msaa: 1,
    }
}

/// One separable SSS pass (floor.rs `separable_pass_cost`): centre colour and
/// depth by texelFetch, n-1 bilinear colour taps and, with follow-surface,
/// n-1 bilinear depth taps.
pub fn separable_shader(samples: u32, follow: bool) -> ShaderWork {
    let taps = f64::from(samples.saturating_sub(1));
    let mut fetches = vec![
        fetch("colorTex", Format::Rgba16Float, Filter::Point, 1.0),
        fetch("depthTex", Format::R32Float, Filter::Point, 1.0),
        fetch("colorTex", Format::Rgba16Float, Filter::Bilinear, taps),
    ];
    if follow {
        fetches.push(fetch("depthTex", Format::R32Float, Filter::Bilinear, taps));
    }
    ShaderWork {
        fetches,
        // Estimate: setup, then per tap an offset, a weight and (follow-surface) the lerp.
        alu: 20.0 + taps * if follow { 12.0 } else { 6.0 },
        ..Default::default()
    }
}

/// One ssg pass (Listing 4.1, floor.rs `ssg_pass_cost`).
pub fn ssg_shader() -> ShaderWork {
    ShaderWork {
        fetches: vec![
            fetch("rt", Format::Rgba16Float, Filter::Point, 1.0),
            fetch("depthTex", Format::R32Float, Filter::Point, 3.0),
            fetch("rt", Format::Rgba16Float, Filter::Bilinear, 7.0),
        ],
        alu: 55.0,
        ..Default::default()
    }
}

fn jittered_shader() -> ShaderWork {
    ShaderWork {
        fetches: vec![
            fetch("colorTex", Format::Rgba16Float, Filter::Point, 1.0),
            fetch("depthTex", Format::R32Float, Filter::Point, 5.0),
            fetch("colorRing", Format::Rgba16Float, Filter::Bilinear, 12.0),
        ],
        alu: 126.0,
        ..Default::default()
    }
}

fn geometry_pass(w: u32, h: u32, heads: u64, normals: bool, fragments: u64) -> PassInput {
    let mut color = vec![
        cw(Format::Rgba16Float, false),
        cw(Format::Rgba16Float, false),
        cw(Format::R32Float, false),
    ];
    let mut images = vec![
        img(
            "shadow map",
            Format::D32Float,
            SHADOW_SIZE,
            SHADOW_SIZE,
            ImageUseKind::Sampled,
        ),
        img(
            "diffuse",
            Format::Rgba16Float,
            w,
            h,
            ImageUseKind::ColorTarget,
        ),
        img(
            "specular",
            Format::Rgba16Float,
            w,
            h,
            ImageUseKind::ColorTarget,
        ),
        img(
            "linear depth",
            Format::R32Float,
            w,
            h,
            ImageUseKind::ColorTarget,
        ),
        img(
            "depth stencil",
            Format::D32FloatS8Uint,
            w,
            h,
            ImageUseKind::DepthTarget,
        ),
    ];
    if normals {
        color.push(cw(Format::Rgba16Float, false));
        images.push(img(
            "normals",
            Format::Rgba16Float,
            w,
            h,
            ImageUseKind::ColorTarget,
        ));
    }
    let px = u64::from(w) * u64::from(h);
    let clears = color
        .iter()
        .map(|c| ClearInput {
            format: c.format,
            texels: px,
        })
        .chain([ClearInput {
            format: Format::D32FloatS8Uint,
            texels: px,
        }])
        .collect();
    let material = Format::Rgba8Srgb;
    let shader = ShaderWork {
        fetches: vec![
            fetch("shadowMap", Format::D32Float, Filter::DepthCompare, 9.0),
            fetch("shadowMap", Format::D32Float, Filter::Point, 1.0),
            fetch("beckmannTex", Format::R16Float, Filter::Bilinear, 1.0),
            fetch("albedoTex", material, Filter::Bilinear, 1.0),
            fetch("normalTex", Format::Rgba8Unorm, Filter::Bilinear, 1.0),
            fetch("specTex", Format::Rgba8Unorm, Filter::Bilinear, 1.0),
        ],
        alu: GEOMETRY_ALU,
        ..Default::default()
    };
    let mut p = PassInput::new(
        "geometry",
        PassRole::Geometry,
        Work::Raster {
            shader: Some(shader),
            color,
            depth_stencil: Some(DepthStencilUse {
                format: Format::D32FloatS8Uint,
                depth_test: true,
                depth_write: true,
                stencil_test: false,
                stencil_write: true,
            }),
            width: w,
            height: h,
            triangles: heads * HEAD_TRIANGLES + 2,
            msaa: 1,
        },
    );
    p.images = images;
    p.clears = clears;
    p.fragments = fragments;
    p.samples_passed = fragments;
    p
}

fn shadow_pass(heads: u64, samples: u64) -> PassInput {
    let s = SHADOW_SIZE;
    let mut p = PassInput::new(
        "shadow map",
        PassRole::Shadow,
        Work::Raster {
            shader: None,
            color: vec![],
            depth_stencil: Some(DepthStencilUse {
                format: Format::D32Float,
                depth_test: true,
                depth_write: true,
                stencil_test: false,
                stencil_write: false,
            }),
            width: s,
            height: s,
            triangles: heads * HEAD_TRIANGLES + 2,
            msaa: 1,
        },
    );
    p.images = vec![img(
        "shadow map",
        Format::D32Float,
        s,
        s,
        ImageUseKind::DepthTarget,
    )];
    p.clears = vec![ClearInput {
        format: Format::D32Float,
        texels: u64::from(s) * u64::from(s),
    }];
    p.samples_passed = samples;
    p
}

fn copy_pass(name: &str, texels: u64, from: &str, to: &[&str], w: u32, h: u32) -> PassInput {
    let mut p = PassInput::new(
        name,
        PassRole::Sss,
        Work::Copy {
            texels,
            bytes_per_texel: 8,
        },
    );
    p.images.push(img(
        from,
        Format::Rgba16Float,
        w,
        h,
        ImageUseKind::CopySource,
    ));
    for t in to {
        p.images.push(img(
            t,
            Format::Rgba16Float,
            w,
            h,
            ImageUseKind::CopyDestination,
        ));
    }
    p
}

fn get<'a>(v: &'a Value, k: &str) -> Result<&'a Value> {
    v.get(k).with_context(|| format!("report has no `{k}`"))
}

fn get_u64(v: &Value, k: &str) -> Result<u64> {
    get(v, k)?
        .as_u64()
        .with_context(|| format!("`{k}` is not an unsigned integer"))
}

/// Rebuilds a report's frame with `rb` applied.
pub fn frame_from_report(path: &Path, rb: Rebuild) -> Result<RunFrame> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let r: Value =
        serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))?;
    let ctx = || format!("{}", path.display());
    let w = get_u64(&r, "width").with_context(ctx)? as u32;
    let h = get_u64(&r, "height").with_context(ctx)? as u32;
    let method = get(&r, "method")?.as_str().unwrap_or_default().to_string();
    let heads = get_u64(&r, "heads").with_context(ctx)?;
    let samples = rb
        .samples
        .unwrap_or(get_u64(&r, "samples").with_context(ctx)? as u32);
    let follow = rb
        .follow_surface
        .unwrap_or(get(&r, "follow_surface")?.as_bool().unwrap_or(true));
    let px = u64::from(w) * u64::from(h);
    let (region, rects) = match rb.region {
        Region::AsRun => (
            get_u64(&r, "sss_region_pixels").unwrap_or(px),
            get_u64(&r, "sss_region_rects").unwrap_or(1),
        ),
        Region::Screen => (px, 1),
    };
    let mut passes = Vec::new();
    for p in get(&r, "passes")?
        .as_array()
        .context("`passes` is not a list")?
    {
        let name = get(p, "name")?.as_str().unwrap_or_default().to_string();
        let frags = get_u64(p, "fragment_invocations").with_context(ctx)?;
        let samples_passed = get_u64(p, "samples_passed").with_context(ctx)?;
        let measured = p
            .get("gpu_ms")
            .and_then(|g| g.get("median"))
            .and_then(Value::as_f64);
        if rb.no_seed_copy && name == "sss seed copy" {
            continue;
        }
        let (frags, samples_passed) = if rb.skinless
            && name != "geometry"
            && name != "shadow map"
            && name != "composite"
            && name != "tonemap"
            && !name.starts_with("poisson mip")
        {
            (0, 0)
        } else {
            (frags, samples_passed)
        };
        let stencil_pass = |work: Work, images: Vec<ImageUse>| {
            let mut q = PassInput::new(&name, PassRole::Sss, work);
            q.images = images;
            q.fragments = frags;
            q.samples_passed = samples_passed;
            q.rasterized_pixels = Some(region.max(frags));
            q
        };
        let mut pass = match name.as_str() {
            "shadow map" => shadow_pass(heads, samples_passed),
            "geometry" => geometry_pass(w, h, heads, method == "poisson", frags),
            "sss seed copy" | "ss-jittered seed copy" => {
                copy_pass(&name, region, "diffuse", &["sss intermediate"], w, h)
            }
            "ssg seed copy" => copy_pass(
                &name,
                2 * region,
                "diffuse",
                &["ssg rt1", "ssg final"],
                w,
                h,
            ),
            "poisson seed copy" => copy_pass(&name, px, "diffuse", &["color chain 0"], w, h),
            "sss horizontal" => stencil_pass(
                post_draw(
                    w,
                    h,
                    separable_shader(samples, follow),
                    vec![cw(Format::Rgba16Float, false)],
                    true,
                    rects,
                ),
                vec![
                    img("diffuse", Format::Rgba16Float, w, h, ImageUseKind::Sampled),
                    img(
                        "linear depth",
                        Format::R32Float,
                        w,
                        h,
                        ImageUseKind::Sampled,
                    ),
                    img(
                        "sss intermediate",
                        Format::Rgba16Float,
                        w,
                        h,
                        ImageUseKind::ColorTargetLoad,
                    ),
                    img(
                        "depth stencil",
                        Format::D32FloatS8Uint,
                        w,
                        h,
                        ImageUseKind::DepthTest,
                    ),
                ],
            ),
            "sss vertical" => stencil_pass(
                post_draw(
                    w,
                    h,
                    separable_shader(samples, follow),
                    vec![cw(Format::Rgba16Float, false)],
                    true,
                    rects,
                ),
                vec![
                    img(
                        "sss intermediate",
                        Format::Rgba16Float,
                        w,
                        h,
                        ImageUseKind::Sampled,
                    ),
                    img(
                        "linear depth",
                        Format::R32Float,
                        w,
                        h,
                        ImageUseKind::Sampled,
                    ),
                    img(
                        "diffuse",
                        Format::Rgba16Float,
                        w,
                        h,
                        ImageUseKind::ColorTargetLoad,
                    ),
                    img(
                        "depth stencil",
                        Format::D32FloatS8Uint,
                        w,
                        h,
                        ImageUseKind::DepthTest,
                    ),
                ],
            ),
            n if n.starts_with("ssg g") && n.ends_with("horizontal") => stencil_pass(
                post_draw(
                    w,
                    h,
                    ssg_shader(),
                    vec![cw(Format::Rgba16Float, false)],
                    true,
                    rects,
                ),
                vec![
                    img("ssg rt1", Format::Rgba16Float, w, h, ImageUseKind::Sampled),
                    img(
                        "linear depth",
                        Format::R32Float,
                        w,
                        h,
                        ImageUseKind::Sampled,
                    ),
                    img(
                        "ssg rt2",
                        Format::Rgba16Float,
                        w,
                        h,
                        ImageUseKind::ColorTargetLoad,
                    ),
                    img(
                        "depth stencil",
                        Format::D32FloatS8Uint,
                        w,
                        h,
                        ImageUseKind::DepthTest,
                    ),
                ],
            ),
            n if n.starts_with("ssg g") && n.ends_with("vertical") => stencil_pass(
                post_draw(
                    w,
                    h,
                    ssg_shader(),
                    vec![
                        cw(Format::Rgba16Float, false),
                        cw(Format::Rgba16Float, true),
                    ],
                    true,
                    rects,
                ),
                vec![
                    img("ssg rt2", Format::Rgba16Float, w, h, ImageUseKind::Sampled),
                    img(
                        "linear depth",
                        Format::R32Float,
                        w,
                        h,
                        ImageUseKind::Sampled,
                    ),
                    img(
                        "ssg rt1",
                        Format::Rgba16Float,
                        w,
                        h,
                        ImageUseKind::ColorTargetLoad,
                    ),
                    img(
                        "ssg final",
                        Format::Rgba16Float,
                        w,
                        h,
                        ImageUseKind::ColorTargetLoad,
                    ),
                    img(
                        "depth stencil",
                        Format::D32FloatS8Uint,
                        w,
                        h,
                        ImageUseKind::DepthTest,
                    ),
                ],
            ),
            "ss-jittered" => {
                let mut q = stencil_pass(
                    post_draw(
                        w,
                        h,
                        jittered_shader(),
                        vec![cw(Format::Rgba16Float, false)],
                        true,
                        rects,
                    ),
                    vec![
                        img("diffuse", Format::Rgba16Float, w, h, ImageUseKind::Sampled),
                        img(
                            "linear depth",
                            Format::R32Float,
                            w,
                            h,
                            ImageUseKind::Sampled,
                        ),
                        img(
                            "sss intermediate",
                            Format::Rgba16Float,
                            w,
                            h,
                            ImageUseKind::ColorTargetLoad,
                        ),
                        img(
                            "depth stencil",
                            Format::D32FloatS8Uint,
                            w,
                            h,
                            ImageUseKind::DepthTest,
                        ),
                    ],
                );
                q.incoherent_textures = vec!["colorRing".into()];
                q
            }
            n if n.starts_with("poisson mip ") => {
                let k: u32 = n["poisson mip ".len()..]
                    .parse()
                    .with_context(|| format!("pass `{n}`"))?;
                let (mw, mh) = (w.div_ceil(1 << k).max(1), h.div_ceil(1 << k).max(1));
                let (sw, sh) = (
                    w.div_ceil(1 << (k - 1)).max(1),
                    h.div_ceil(1 << (k - 1)).max(1),
                );
                let shader = ShaderWork {
                    fetches: vec![
                        fetch("srcColor", Format::Rgba16Float, Filter::Point, 4.0),
                        fetch("srcDepth", Format::R32Float, Filter::Point, 4.0),
                        fetch("srcNormal", Format::Rgba16Float, Filter::Point, 4.0),
                    ],
                    alu: 15.0,
                    ..Default::default()
                };
                let mut q = PassInput::new(
                    &name,
                    PassRole::Sss,
                    post_draw(
                        mw,
                        mh,
                        shader,
                        vec![
                            cw(Format::Rgba16Float, false),
                            cw(Format::R32Float, false),
                            cw(Format::Rgba16Float, false),
                        ],
                        false,
                        1,
                    ),
                );
                q.images = vec![
                    img(
                        &format!("color chain {}", k - 1),
                        Format::Rgba16Float,
                        sw,
                        sh,
                        ImageUseKind::Sampled,
                    ),
                    img(
                        &format!("color chain {k}"),
                        Format::Rgba16Float,
                        mw,
                        mh,
                        ImageUseKind::ColorTarget,
                    ),
                ];
                q.fragments = frags;
                q.samples_passed = samples_passed;
                q
            }
            "poisson" => {
                let t = POISSON_TAPS_ASSUMED;
                let shader = ShaderWork {
                    fetches: vec![
                        fetch("colorChain", Format::Rgba16Float, Filter::Point, 1.0),
                        fetch("depthChain", Format::R32Float, Filter::Point, 1.0),
                        fetch("normalChain", Format::Rgba16Float, Filter::Point, 1.0),
                        fetch("colorChain", Format::Rgba16Float, Filter::Bilinear, t),
                        fetch("depthChain", Format::R32Float, Filter::Bilinear, t),
                        fetch("normalChain", Format::Rgba16Float, Filter::Bilinear, t),
                    ],
                    alu: 30.0 + 25.0 * t,
                    ..Default::default()
                };
                stencil_pass(
                    post_draw(
                        w,
                        h,
                        shader,
                        vec![cw(Format::Rgba16Float, false)],
                        true,
                        rects,
                    ),
                    vec![
                        img(
                            "color chain 0",
                            Format::Rgba16Float,
                            w,
                            h,
                            ImageUseKind::Sampled,
                        ),
                        img(
                            "diffuse",
                            Format::Rgba16Float,
                            w,
                            h,
                            ImageUseKind::ColorTargetLoad,
                        ),
                        img(
                            "depth stencil",
                            Format::D32FloatS8Uint,
                            w,
                            h,
                            ImageUseKind::DepthTest,
                        ),
                    ],
                )
            }
            "composite" => {
                let sss_out = match method.as_str() {
                    "ssg" => "ssg final",
                    _ => "diffuse",
                };
                let mut q = PassInput::new(
                    &name,
                    PassRole::Post,
                    post_draw(
                        w,
                        h,
                        ShaderWork {
                            fetches: vec![fetch("sss", Format::Rgba16Float, Filter::Point, 2.0)],
                            alu: 10.0,
                            ..Default::default()
                        },
                        vec![cw(Format::Rgba16Float, false)],
                        false,
                        1,
                    ),
                );
                q.images = vec![
                    img(sss_out, Format::Rgba16Float, w, h, ImageUseKind::Sampled),
                    img("specular", Format::Rgba16Float, w, h, ImageUseKind::Sampled),
                    img("hdr", Format::Rgba16Float, w, h, ImageUseKind::ColorTarget),
                ];
                q.fragments = frags;
                q.samples_passed = samples_passed;
                q
            }
            "tonemap" => {
                let mut q = PassInput::new(
                    &name,
                    PassRole::Post,
                    post_draw(
                        w,
                        h,
                        ShaderWork {
                            fetches: vec![fetch("hdr", Format::Rgba16Float, Filter::Point, 1.0)],
                            alu: 20.0,
                            ..Default::default()
                        },
                        vec![cw(Format::Rgba8Srgb, false)],
                        false,
                        1,
                    ),
                );
                q.images = vec![
                    img("hdr", Format::Rgba16Float, w, h, ImageUseKind::Sampled),
                    img("ldr", Format::Rgba8Srgb, w, h, ImageUseKind::ColorTarget),
                ];
                q.fragments = frags;
                q.samples_passed = samples_passed;
                q
            }
            other => bail!("{}: no work known for pass `{other}`", path.display()),
        };
        pass.measured_ms = measured;
        passes.push(pass);
    }
    let file = path
        .strip_prefix(perf_dir())
        .unwrap_or(path)
        .display()
        .to_string();
    Ok(RunFrame {
        file: file.clone(),
        method,
        heads: heads as u32,
        frame: FrameInput {
            label: file,
            width: w,
            height: h,
            passes,
        },
    })
}

/// The bench matrix and the issue-2 shots of `docs/perf/h100/` (top level),
/// as run.
pub fn h100_frames() -> Result<Vec<RunFrame>> {
    let dir = perf_dir().join("h100");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .with_context(|| format!("listing {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    files
        .iter()
        .map(|f| frame_from_report(f, Rebuild::default()))
        .collect()
}

/// Jimenez's MLAA (thesis 000 ch. 9) at `w` x `h` from first principles: edge
/// detection on every pixel (5 point fetches of the colour, luminance
/// variant), then blending weights and neighbourhood blending on edge pixels
/// only (stencil). `edge_share` of the pixels are edges (an assumption: the
/// thesis gives no count); the weights pass searches `search_taps` bilinear
/// taps on average (its loops stop at the edge's end) plus 2 area-texture and
/// 1 edge fetch; blending makes 3 point and 4 bilinear fetches.
pub fn mlaa_frame(w: u32, h: u32, edge_share: f64, search_taps: f64) -> FrameInput {
    let px = u64::from(w) * u64::from(h);
    let edges = (px as f64 * edge_share).round() as u64;
    let stencil_write = DepthStencilUse {
        format: Format::D24UnormS8Uint,
        depth_test: false,
        depth_write: false,
        stencil_test: false,
        stencil_write: true,
    };
    let stencil_test = DepthStencilUse {
        stencil_test: true,
        stencil_write: false,
        ..stencil_write
    };
    let draw = |shader: ShaderWork, out: Format, ds: DepthStencilUse| Work::Raster {
        shader: Some(shader),
        color: vec![cw(out, false)],
        depth_stencil: Some(ds),
        width: w,
        height: h,
        triangles: 2,
        msaa: 1,
    };
    let mut detect = PassInput::new(
        "mlaa edge detection",
        PassRole::Post,
        draw(
            ShaderWork {
                fetches: vec![fetch("colorTex", Format::Rgba8Unorm, Filter::Point, 5.0)],
                alu: 25.0,
                ..Default::default()
            },
            Format::Rgba8Unorm,
            stencil_write,
        ),
    );
    // Every pixel runs the shader; only edges are written (the rest discard).
    detect.fragments = px;
    detect.samples_passed = edges;
    detect.clears = vec![
        ClearInput {
            format: Format::Rgba8Unorm,
            texels: px,
        },
        ClearInput {
            format: Format::D24UnormS8Uint,
            texels: px,
        },
    ];
    detect.images = vec![
        img("color", Format::Rgba8Unorm, w, h, ImageUseKind::Sampled),
        img("edges", Format::Rgba8Unorm, w, h, ImageUseKind::ColorTarget),
        img(
            "stencil",
            Format::D24UnormS8Uint,
            w,
            h,
            ImageUseKind::DepthTarget,
        ),
    ];
    let mut weights = PassInput::new(
        "mlaa blending weights",
        PassRole::Post,
        draw(
            ShaderWork {
                fetches: vec![
                    fetch("edgesTex", Format::Rgba8Unorm, Filter::Point, 1.0),
                    fetch(
                        "edgesTex",
                        Format::Rgba8Unorm,
                        Filter::Bilinear,
                        search_taps,
                    ),
                    fetch("areaTex", Format::Rgba8Unorm, Filter::Point, 2.0),
                ],
                alu: 20.0 + 4.0 * search_taps,
                ..Default::default()
            },
            Format::Rgba8Unorm,
            stencil_test,
        ),
    );
    weights.fragments = edges;
    weights.samples_passed = edges;
    weights.rasterized_pixels = Some(px);
    weights.clears = vec![ClearInput {
        format: Format::Rgba8Unorm,
        texels: px,
    }];
    weights.images = vec![
        img("edges", Format::Rgba8Unorm, w, h, ImageUseKind::Sampled),
        img(
            "weights",
            Format::Rgba8Unorm,
            w,
            h,
            ImageUseKind::ColorTarget,
        ),
        img(
            "stencil",
            Format::D24UnormS8Uint,
            w,
            h,
            ImageUseKind::DepthTest,
        ),
    ];
    let mut blend = PassInput::new(
        "mlaa neighbourhood blending",
        PassRole::Post,
        draw(
            ShaderWork {
                fetches: vec![
                    fetch("blendTex", Format::Rgba8Unorm, Filter::Point, 3.0),
                    fetch("colorTex", Format::Rgba8Unorm, Filter::Bilinear, 4.0),
                ],
                alu: 20.0,
                ..Default::default()
            },
            Format::Rgba8Unorm,
            stencil_test,
        ),
    );
    blend.fragments = edges;
    blend.samples_passed = edges;
    blend.rasterized_pixels = Some(px);
    blend.images = vec![
        img("weights", Format::Rgba8Unorm, w, h, ImageUseKind::Sampled),
        img("color", Format::Rgba8Unorm, w, h, ImageUseKind::Sampled),
        img(
            "output",
            Format::Rgba8Unorm,
            w,
            h,
            ImageUseKind::ColorTargetLoad,
        ),
        img(
            "stencil",
            Format::D24UnormS8Uint,
            w,
            h,
            ImageUseKind::DepthTest,
        ),
        img("output", Format::Rgba8Unorm, w, h, ImageUseKind::Host),
    ];
    FrameInput {
        label: format!("MLAA {w}x{h}, {:.0}% edge pixels", edge_share * 100.0),
        width: w,
        height: h,
        passes: vec![detect, weights, blend],
    }
}

/// Seed 001's "Gaussian sum": six Gaussians, each a horizontal and a vertical
/// pass of `samples` colour and depth taps (its Figure 3.4 shader), built from
/// a separable frame's SSS passes: each of its two blur passes repeated six
/// times, the rest unchanged. Not a dermis method: first principles.
pub fn six_gaussian_frame(separable: &FrameInput, samples: u32) -> FrameInput {
    let mut passes = Vec::new();
    for p in &separable.passes {
        if p.name == "sss horizontal" || p.name == "sss vertical" {
            for g in 1..=6 {
                let mut q = p.clone();
                q.name = format!("{} g{g}", p.name);
                if let Work::Raster { shader, .. } = &mut q.work {
                    *shader = Some(separable_shader(samples, true));
                }
                q.measured_ms = None;
                passes.push(q);
            }
        } else {
            passes.push(p.clone());
        }
    }
    FrameInput {
        label: format!("{} as seed 001's six-Gaussian sum", separable.label),
        width: separable.width,
        height: separable.height,
        passes,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_h100_report_rebuilds() {
        let frames = h100_frames().unwrap();
        assert!(frames.len() >= 96, "{}", frames.len());
        for f in &frames {
            assert!(
                f.frame.passes.iter().all(|p| p.measured_ms.is_some()),
                "{}",
                f.file
            );
            assert_eq!(f.frame.passes[0].name, "shadow map");
        }
        let sep = frames
            .iter()
            .find(|f| f.file.ends_with("sep_1080p_close_s17.json"))
            .unwrap();
        let h = &sep.frame.passes[3];
        assert_eq!(h.name, "sss horizontal");
        assert_eq!(h.fragments, 668_926);
        assert_eq!(h.rasterized_pixels, Some(927_488));
    }

    #[test]
    fn rebuild_overrides_apply() {
        let path = perf_dir().join("h100/sep_1080p_close_s17.json");
        let rb = Rebuild {
            region: Region::Screen,
            samples: Some(9),
            follow_surface: Some(false),
            ..Rebuild::default()
        };
        let f = frame_from_report(&path, rb).unwrap().frame;
        let copy = &f.passes[2];
        assert!(matches!(
            copy.work,
            Work::Copy {
                texels: 2_073_600,
                ..
            }
        ));
        let Work::Raster {
            shader: Some(s), ..
        } = &f.passes[3].work
        else {
            panic!()
        };
        assert_eq!(s.fetches.len(), 3);
        assert_eq!(s.fetches[2].count, 8.0);
    }
}
