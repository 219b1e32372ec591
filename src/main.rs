//! The `dermis` command line. Only argument handling lives here; the work is in
//! the library (`dermis::run`).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{bail, Context as _, Result};
use clap::{Args, Parser, Subcommand, ValueEnum};

use dermis::render::{Method, RenderSettings};
use dermis::run::{read_exr, run, slug, write_diffuse_exr, write_exr, write_png, RunOptions};
use dermis::scene::camera::Camera;
use dermis::scene::gltf_load::TextureOverrides;
use dermis::scene::{default_scene, load_gltf_scene, Scene};
use dermis::skin::kernel::{Preset, SeparableKernel};
use dermis::vk::context::{Context, ContextDesc, DeviceChoice};

#[derive(Parser)]
#[command(
    name = "dermis",
    version,
    about = "Real-time skin rendering (Vulkan) that measures every pass"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a frame: writes DIR/frame.png and DIR/report.json and prints the per-pass table.
    Render {
        #[command(flatten)]
        common: Common,
        /// Output directory.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Also write every pass output as linear EXR under DIR/passes/.
        #[arg(long)]
        dump: bool,
        #[arg(long, default_value_t = 3)]
        warmup: usize,
        #[arg(long, default_value_t = 10)]
        frames: usize,
    },
    /// Measure many frames and the device ceilings; writes the report only.
    Bench {
        #[command(flatten)]
        common: Common,
        /// Report path (JSON).
        #[arg(long, default_value = "out/bench.json")]
        report: PathBuf,
        #[arg(long, default_value_t = 20)]
        warmup: usize,
        #[arg(long, default_value_t = 100)]
        frames: usize,
    },
    /// Render the ground truth (brute-force integral over the skin surface): like
    /// `render --method reference`, writes frame.png, diffuse.exr and report.json.
    Reference {
        #[command(flatten)]
        common: Common,
        #[arg(long, default_value = "out/reference")]
        out: PathBuf,
    },
    /// Compare two render outputs (DIR with diffuse.exr and frame.png): relative
    /// RMSE of the linear diffuse over skin pixels (skin from B) and FLIP of the
    /// tone-mapped frames; writes error images and compare.json into --out.
    Compare {
        /// The image under test.
        a: PathBuf,
        /// The reference.
        b: PathBuf,
        /// Where to write the error images (default: A).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Sweep every registered method and setting over a scene set against the
    /// ground truth: writes eval.csv, eval.json and the cost/error chart (PNG, SVG).
    Eval {
        #[command(flatten)]
        common: Common,
        #[arg(long, default_value = "out/eval")]
        out: PathBuf,
        /// Scene set: thesis (the Lee Perry-Smith head at the perceptual study's 3
        /// distances x 4 lights, plus the procedural scene), dolly (the head from 1 to
        /// 24 head heights in 12 steps; adds distance.png/svg, error against distance)
        /// or quick (procedural only).
        #[arg(long, default_value = "thesis")]
        scenes: String,
        #[arg(long, default_value_t = 2)]
        warmup: usize,
        #[arg(long, default_value_t = 10)]
        frames: usize,
    },
    /// Print the separable SSS kernel (offsets in mm and RGB weights) as JSON.
    Kernel {
        #[arg(long, default_value_t = 17)]
        samples: usize,
        #[arg(long, default_value = "table6.1")]
        preset: String,
        /// Override the preset's width (mm).
        #[arg(long)]
        width_mm: Option<f32>,
    },
    /// List the Vulkan devices.
    Devices {
        #[arg(long)]
        validate: bool,
    },
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum Shot {
    /// The head fills the screen height.
    Close,
    /// Twice the close-up distance.
    Mid,
    /// Five times the close-up distance.
    Far,
}

#[derive(Args)]
struct Common {
    /// Vulkan device: index or case-insensitive name substring (default: first discrete GPU).
    #[arg(long)]
    device: Option<String>,
    /// Enable the Khronos validation layer with synchronization validation; any message fails the run.
    #[arg(long)]
    validate: bool,
    /// glTF/GLB scene (default: the embedded procedural head).
    #[arg(long)]
    scene: Option<PathBuf>,
    #[arg(long)]
    albedo: Option<PathBuf>,
    #[arg(long)]
    normal_map: Option<PathBuf>,
    #[arg(long)]
    spec_map: Option<PathBuf>,
    /// Texture files beside the scene (or given above) are top-down; by default they
    /// are taken as bottom-up (OpenGL convention), as the Lee Perry-Smith head's are.
    #[arg(long)]
    sidecar_top_down: bool,
    /// Scene scale in millimetres per unit (default: from a 230 mm chin-to-crown head).
    #[arg(long)]
    mm_per_unit: Option<f32>,
    #[arg(long, default_value_t = 1280)]
    width: u32,
    #[arg(long, default_value_t = 720)]
    height: u32,
    /// SSS method: separable | ssg | ss-jittered | poisson | reference | none.
    #[arg(long, default_value = "separable")]
    method: String,
    /// Kernel samples per SSS pass (odd: 9, 17, 33, ...).
    #[arg(long, default_value_t = 17)]
    samples: usize,
    /// Kernel preset: table6.1 | demo.
    #[arg(long, default_value = "table6.1")]
    preset: String,
    /// Override the kernel half-width in millimetres.
    #[arg(long)]
    sss_width_mm: Option<f32>,
    /// Override the per-channel strength: R,G,B.
    #[arg(long, value_delimiter = ',')]
    strength: Option<Vec<f32>>,
    /// Override the per-channel falloff: R,G,B.
    #[arg(long, value_delimiter = ',')]
    falloff: Option<Vec<f32>>,
    #[arg(long)]
    no_follow_surface: bool,
    /// Transmittance T(s): thesis (eq. 5.12 as published) or integral (the profile
    /// integrated over a plane: exp(-s^2 / 2v), see docs/accuracy.md).
    #[arg(long, default_value = "thesis")]
    transmittance_profile: String,
    /// reference: surface samples per mm^2 (32 is converged: doubling it changes
    /// the image by 5e-4 relative RMSE).
    #[arg(long, default_value_t = 32.0)]
    density: f32,
    /// ssg: Gaussian fit of thesis Table 4.2: 6 or 4.
    #[arg(long, default_value = "6")]
    fit: String,
    /// ssg: draw every Gaussian everywhere (no depth-based level of detail).
    #[arg(long)]
    no_lod: bool,
    /// ssg: keep non-skin pixels out with the stencil test or a shader branch: stencil | branch.
    #[arg(long, default_value = "stencil")]
    mask: String,
    /// Where the SSS passes run: skin (the skin's projected bounds widened by the
    /// kernel's reach: seed copies and draws limited to them) | screen (everywhere).
    #[arg(long, default_value = "skin")]
    sss_region: String,
    /// Side of the SSS region's screen tiles in pixels (1..=1024): smaller hugs the
    /// skin closer but draws more rectangles.
    #[arg(long, default_value_t = dermis::render::region::TILE_PX)]
    sss_region_tile: u32,
    #[arg(long)]
    no_transmittance: bool,
    /// Number of heads in a grid (multi-character stress).
    #[arg(long, default_value_t = 1)]
    heads: u32,
    /// Camera shot (ignored when --distance is given).
    #[arg(long, value_enum, default_value_t = Shot::Mid)]
    shot: Shot,
    /// Camera distance from the head centre in head heights.
    #[arg(long)]
    distance: Option<f32>,
    /// Vertical field of view in degrees.
    #[arg(long, default_value_t = 20.0)]
    fovy: f32,
    /// Key light azimuth in degrees (0 = from the camera side, positive toward the viewer's right).
    #[arg(long, default_value_t = 60.0, allow_negative_numbers = true)]
    light_azimuth: f32,
    /// Key light elevation in degrees above the horizon.
    #[arg(long, default_value_t = 30.0, allow_negative_numbers = true)]
    light_elevation: f32,
    #[arg(long, default_value_t = 2.5)]
    light_intensity: f32,
    #[arg(long, default_value_t = 0.08)]
    ambient: f32,
    #[arg(long, default_value_t = 2.0)]
    exposure: f32,
    #[arg(long, default_value_t = 2048)]
    shadow_size: u32,
}

impl Common {
    fn settings(&self) -> Result<RenderSettings> {
        let preset: Preset = self.preset.parse()?;
        let mut params = preset.params();
        if let Some(w) = self.sss_width_mm {
            params.width_mm = w;
        }
        let rgb = |what: &str, v: &[f32]| -> Result<[f32; 3]> {
            match v {
                [r, g, b] => Ok([*r, *g, *b]),
                _ => bail!(
                    "--{what} takes three comma-separated values R,G,B, got {}",
                    v.len()
                ),
            }
        };
        if let Some(s) = &self.strength {
            params.strength = rgb("strength", s)?;
        }
        if let Some(f) = &self.falloff {
            params.falloff = rgb("falloff", f)?;
        }
        let close = Camera::close_up_distance_heads(self.fovy);
        let distance = self.distance.unwrap_or(match self.shot {
            Shot::Close => close,
            Shot::Mid => 2.0 * close,
            Shot::Far => 5.0 * close,
        });
        let mut s = RenderSettings {
            width: self.width,
            height: self.height,
            method: self.method.parse::<Method>()?,
            samples: self.samples,
            preset,
            params,
            follow_surface: !self.no_follow_surface,
            transmittance: !self.no_transmittance,
            fit: self.fit.parse()?,
            lod: !self.no_lod,
            mask: self.mask.parse()?,
            sss_region: self.sss_region.parse()?,
            sss_region_tile: self.sss_region_tile,
            reference_density: self.density,
            transmittance_profile: self.transmittance_profile.parse()?,
            heads: self.heads,
            distance_heads: distance,
            fovy_deg: self.fovy,
            ..RenderSettings::default()
        };
        s.light.azimuth_deg = self.light_azimuth;
        s.light.elevation_deg = self.light_elevation;
        s.light.intensity = self.light_intensity;
        s.ambient = self.ambient;
        s.exposure = self.exposure;
        s.shadow_size = self.shadow_size;
        // Checked again against the device limits once a device is open.
        s.validate(u32::MAX)?;
        Ok(s)
    }

    fn scene(&self) -> Result<Scene> {
        match &self.scene {
            None => {
                let mut s = default_scene();
                if let Some(mm) = self.mm_per_unit {
                    if !mm.is_finite() || mm <= 0.0 {
                        bail!("mm_per_unit must be a positive number, got {mm}");
                    }
                    s.mm_per_unit = mm;
                }
                Ok(s)
            }
            Some(p) => load_gltf_scene(
                p,
                &TextureOverrides {
                    albedo: self.albedo.clone(),
                    normal_map: self.normal_map.clone(),
                    specular_map: self.spec_map.clone(),
                    sidecar_top_down: self.sidecar_top_down,
                },
                self.mm_per_unit,
            ),
        }
    }

    fn context(&self) -> Result<Context> {
        Context::new(&ContextDesc {
            device: self
                .device
                .as_deref()
                .map(|d| d.parse::<DeviceChoice>().unwrap_or_default())
                .unwrap_or_default(),
            validate: self.validate,
        })
    }
}

fn command_line() -> String {
    std::env::args().collect::<Vec<_>>().join(" ")
}

fn print_header(ctx: &Context, r: &dermis::run::Report) {
    println!(
        "dermis {} | {} ({}) | {}x{} | method {} | {} samples | scene '{}' ({:.1} mm/unit) | {} head(s) | {} measured frames",
        r.dermis_version, ctx.facts.name, ctx.facts.driver, r.width, r.height, r.method, r.samples, r.scene, r.mm_per_unit, r.heads, r.measured_frames
    );
}

fn main_result() -> Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Render {
            common,
            out,
            dump,
            warmup,
            frames,
        } => {
            let settings = common.settings()?;
            render_to(&common, settings, &out, dump, warmup, frames)?;
        }
        Command::Reference { common, out } => {
            let settings = RenderSettings {
                method: Method::Reference,
                ..common.settings()?
            };
            render_to(&common, settings, &out, false, 0, 1)?;
        }
        Command::Compare { a, b, out } => compare(&a, &b, out.as_deref().unwrap_or(&a))?,
        Command::Eval {
            common,
            out,
            scenes,
            warmup,
            frames,
        } => eval(&common, &out, &scenes, warmup, frames)?,
        Command::Bench {
            common,
            report,
            warmup,
            frames,
        } => {
            let settings = common.settings()?;
            let scene = common.scene()?;
            let ctx = common.context()?;
            let opts = RunOptions {
                warmup,
                measured: frames,
                capture: false,
                dump: false,
                ceilings: true,
                command: command_line(),
                progress: true,
            };
            let output = run(&ctx, &scene, &settings, &opts)?;
            if let Some(parent) = report.parent().filter(|p| !p.as_os_str().is_empty()) {
                std::fs::create_dir_all(parent)
                    .with_context(|| format!("creating {}", parent.display()))?;
            }
            std::fs::write(&report, serde_json::to_string_pretty(&output.report)?)
                .with_context(|| format!("writing {}", report.display()))?;
            print_header(&ctx, &output.report);
            print!(
                "{}",
                dermis::report::table(&output.report.passes, output.report.frame.as_ref())
            );
            if let Some(c) = &output.report.ceilings {
                println!(
                    "ceilings: bilinear rgba16f {:.1} Gtap/s, point rgba16f {:.1}, bilinear r32f {:.1}, point r32f {:.1}; fill rgba16f {:.2} Gpix/s, rgba8 {:.2}, blended rgba16f {:.2}",
                    c.bilinear_rgba16f_gtaps, c.point_rgba16f_gtaps, c.bilinear_r32f_gtaps, c.point_r32f_gtaps, c.fill_rgba16f_gpix, c.fill_rgba8_gpix, c.blend_rgba16f_gpix
                );
            }
            println!("wrote {}", report.display());
        }
        Command::Kernel {
            samples,
            preset,
            width_mm,
        } => {
            let preset: Preset = preset.parse()?;
            let mut params = preset.params();
            if let Some(w) = width_mm {
                params.width_mm = w;
            }
            params.validate()?;
            let k = SeparableKernel::build(params, samples)?;
            println!(
                "{}",
                serde_json::to_string_pretty(
                    &serde_json::json!({ "preset": preset.name(), "samples": samples, "kernel": k })
                )?
            );
        }
        Command::Devices { validate } => {
            let ctx = Context::new(&ContextDesc {
                device: DeviceChoice::Auto,
                validate,
            })?;
            let devices = unsafe { ctx.instance.enumerate_physical_devices() }?;
            for (i, d) in devices.iter().enumerate() {
                let p = unsafe { ctx.instance.get_physical_device_properties(*d) };
                let name = p
                    .device_name_as_c_str()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default();
                println!("{i}: {name} ({:?})", p.device_type);
            }
        }
    }
    Ok(())
}

/// Renders `settings` and writes frame.png, diffuse.exr, report.json (and with
/// `dump`, every pass output) into `out`, printing the per-pass table.
fn render_to(
    common: &Common,
    settings: RenderSettings,
    out: &std::path::Path,
    dump: bool,
    warmup: usize,
    frames: usize,
) -> Result<()> {
    let scene = common.scene()?;
    let ctx = common.context()?;
    let opts = RunOptions {
        warmup,
        measured: frames,
        capture: true,
        dump,
        ceilings: false,
        command: command_line(),
        progress: true,
    };
    let output = run(&ctx, &scene, &settings, &opts)?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let capture = output.capture.as_ref().context("no frame was captured")?;
    write_png(&out.join("frame.png"), capture)?;
    write_diffuse_exr(&out.join("diffuse.exr"), capture)?;
    if dump {
        let dir = out.join("passes");
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        for (i, d) in capture.dumps.iter().enumerate() {
            write_exr(
                &dir.join(format!("{:02}_{}_{}.exr", i, slug(&d.pass), slug(&d.image))),
                d,
            )?;
        }
    }
    let json = serde_json::to_string_pretty(&output.report)?;
    std::fs::write(out.join("report.json"), json)
        .with_context(|| format!("writing {}", out.join("report.json").display()))?;
    print_header(&ctx, &output.report);
    print!(
        "{}",
        dermis::report::table(&output.report.passes, output.report.frame.as_ref())
    );
    println!(
        "wrote {}, {} and {}",
        out.join("frame.png").display(),
        out.join("diffuse.exr").display(),
        out.join("report.json").display()
    );
    Ok(())
}

/// `dermis eval`: the sweep, its CSV and JSON, and the chart.
fn eval(
    common: &Common,
    out: &std::path::Path,
    scenes: &str,
    warmup: usize,
    frames: usize,
) -> Result<()> {
    use dermis::eval::{chart, pareto, sweep};
    let base = common.settings()?;
    let head = || -> Result<std::path::PathBuf> {
        let head = match &common.scene {
            Some(p) => p.clone(),
            None => std::path::PathBuf::from("../shared/assets/lee-perry-smith/LeePerrySmith.glb"),
        };
        if !head.exists() {
            bail!("the '{scenes}' scene set needs the head scan: {} not found (give --scene PATH.glb, or --scenes quick)", head.display());
        }
        Ok(head)
    };
    let specs = match scenes {
        "thesis" => sweep::thesis_scenes(Some(head()?)),
        "dolly" => sweep::dolly_scenes(head()?),
        "quick" => vec![sweep::SceneSpec {
            distance_heads: base.distance_heads,
            ..sweep::procedural_scene()
        }],
        other => bail!("unknown scene set '{other}' (valid: thesis, dolly, quick)"),
    };
    let ctx = common.context()?;
    let rows = sweep::sweep(
        &ctx,
        &specs,
        &sweep::registry(),
        &sweep::EvalOptions {
            base,
            warmup,
            measured: frames,
            progress: true,
        },
    )?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let points: Vec<pareto::EvalPoint> = rows.iter().map(|r| r.point.clone()).collect();
    pareto::write_csv(&out.join("eval.csv"), &points)?;
    let summary = sweep::summarise(&rows);
    let report = serde_json::json!({
        "device": ctx.facts.name, "driver": ctx.facts.driver, "command": command_line(),
        "scenes": specs, "rows": rows, "summary": summary,
        "pareto_front": pareto::pareto_front(&summary).iter().map(|&i| &summary[i]).collect::<Vec<_>>(),
    });
    std::fs::write(
        out.join("eval.json"),
        serde_json::to_string_pretty(&report)?,
    )?;
    chart::cost_error_chart(
        &summary,
        &format!(
            "SSS cost vs error ({}, {} scene(s))",
            ctx.facts.name,
            specs.len()
        ),
        "GPU ms (SSS passes, median)",
        &out.join("chart.png"),
        &out.join("chart.svg"),
    )?;
    println!(
        "{:<12} {:<26} {:>10} {:>12}",
        "method", "setting", "SSS ms", "rel. RMSE"
    );
    for p in &summary {
        println!(
            "{:<12} {:<26} {:>10.4} {:>12.4e}",
            p.method, p.setting, p.gpu_ms, p.error
        );
    }
    if scenes == "dolly" {
        // Error against distance, one line per (method, setting): where a
        // distance-driven switch changes the image, the line steps.
        // One line per method at its default setting (eval.csv has them all).
        const LINES: [(&str, &str); 6] = [
            ("none", "-"),
            ("separable", "17 samples"),
            ("ssg", "6 Gaussians, LOD"),
            ("ssg", "6 Gaussians, no LOD"),
            ("ss-jittered", "13 taps"),
            ("poisson", "8-32 taps"),
        ];
        let mut series: Vec<chart::Series> = Vec::new();
        for r in &rows {
            let p = &r.point;
            if !LINES.contains(&(p.method.as_str(), p.setting.as_str())) {
                continue;
            }
            let Some(spec) = specs.iter().find(|s| s.name == p.scene) else {
                continue;
            };
            let label = format!("{} {}", p.method, p.setting);
            let point = (spec.distance_heads as f64, p.error);
            match series.iter_mut().find(|s| s.label == label) {
                Some(s) => s.points.push(point),
                None => series.push(chart::Series {
                    label,
                    points: vec![point],
                }),
            }
        }
        chart::series_chart(
            &series,
            &format!("SSS error along a dolly ({})", ctx.facts.name),
            "camera distance (head heights)",
            "relative RMSE against the reference",
            &out.join("distance.png"),
            &out.join("distance.svg"),
        )?;
    }
    println!(
        "wrote eval.csv, eval.json, chart.png and chart.svg{} in {}",
        if scenes == "dolly" {
            ", distance.png and distance.svg"
        } else {
            ""
        },
        out.display()
    );
    Ok(())
}

/// `dermis compare A B`: metrics of A against the reference B.
fn compare(a: &std::path::Path, b: &std::path::Path, out: &std::path::Path) -> Result<()> {
    use dermis::eval::metrics::{abs_error_map, false_colour, flip_ldr, relative_rmse};
    let (wa, ha, da) = read_exr(&a.join("diffuse.exr"))?;
    let (wb, hb, db) = read_exr(&b.join("diffuse.exr"))?;
    if (wa, ha) != (wb, hb) {
        bail!(
            "{} is {wa}x{ha} but {} is {wb}x{hb}",
            a.display(),
            b.display()
        );
    }
    let load_png = |d: &std::path::Path| -> Result<Vec<u8>> {
        let p = d.join("frame.png");
        Ok(image::open(&p)
            .with_context(|| format!("reading {}", p.display()))?
            .to_rgba8()
            .into_raw())
    };
    let (fa, fb) = (load_png(a)?, load_png(b)?);
    let mask: Vec<bool> = db.iter().map(|p| p[3] > 0.0).collect();
    let rmse = relative_rmse(&da, &db, &mask)?;
    let flip = flip_ldr(&fa, &fb, wa, ha)?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let save = |name: &str, rgba: Vec<u8>| -> Result<()> {
        let p = out.join(name);
        image::RgbaImage::from_raw(wa, ha, rgba)
            .context("error image size")?
            .save(&p)
            .with_context(|| format!("writing {}", p.display()))
    };
    // Relative diffuse error, 0..10% mapped onto the colour ramp.
    save(
        "error_diffuse.png",
        false_colour(&abs_error_map(&da, &db, &mask), wa, ha, 0.1),
    )?;
    save("error_flip.png", false_colour(&flip.error_map, wa, ha, 1.0))?;
    let report = serde_json::json!({
        "test": a.display().to_string(),
        "reference": b.display().to_string(),
        "skin_pixels": mask.iter().filter(|&&m| m).count(),
        "relative_rmse": rmse,
        "flip_mean": flip.mean,
    });
    std::fs::write(
        out.join("compare.json"),
        serde_json::to_string_pretty(&report)?,
    )?;
    println!("relative RMSE (linear diffuse, skin) {rmse:.4e} | FLIP (tone-mapped) {:.4} | error images in {}", flip.mean, out.display());
    Ok(())
}

fn main() -> ExitCode {
    match main_result() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // One line: the error and its causes.
            eprintln!("error: {}", format!("{e:#}").replace('\n', " | "));
            ExitCode::FAILURE
        }
    }
}
