//! Shared set-up of the GPU tests: lavapipe, validation with synchronization
//! validation always on (any message fails the test), and the shared test asset.
#![allow(dead_code)]

use std::path::PathBuf;

use dermis::vk::context::{Context, ContextDesc, DeviceChoice};

/// The test device: lavapipe unless DERMIS_TEST_DEVICE names another.
pub fn ctx() -> Context {
    let name = std::env::var("DERMIS_TEST_DEVICE").unwrap_or_else(|_| "llvmpipe".into());
    Context::new(&ContextDesc { device: DeviceChoice::Name(name), validate: true, count_fetches: false })
        .expect("creating a validated Vulkan context on lavapipe (install mesa-vulkan-drivers and vulkan-validationlayers)")
}

/// The Lee Perry-Smith head beside the project (`../shared/assets`). Under CI it
/// must exist; elsewhere a missing asset skips the test that needs it.
pub fn lps_path() -> Option<PathBuf> {
    let candidates = [
        std::env::var("DERMIS_ASSETS").ok().map(PathBuf::from),
        Some(PathBuf::from(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../shared/assets/lee-perry-smith/LeePerrySmith.glb"
        ))),
    ];
    for c in candidates.into_iter().flatten() {
        let p = if c.is_dir() {
            c.join("LeePerrySmith.glb")
        } else {
            c
        };
        if p.exists() {
            return Some(p);
        }
    }
    if std::env::var_os("CI").is_some() {
        panic!("the Lee Perry-Smith head is missing: CI needs ../shared/assets/lee-perry-smith beside the project");
    }
    None
}

/// A registered method by CLI name.
pub fn m(name: &str) -> &'static dermis::method::MethodEntry {
    dermis::method::lookup(name).expect("a registered method")
}

/// The test device with every pipeline built from the fetch-counting build of
/// its shaders (see `dermis::render::counting`).
pub fn counting_ctx() -> Context {
    let name = std::env::var("DERMIS_TEST_DEVICE").unwrap_or_else(|_| "llvmpipe".into());
    Context::new(&ContextDesc {
        device: DeviceChoice::Name(name),
        validate: true,
        count_fetches: true,
    })
    .expect("creating a validated, fetch-counting Vulkan context on lavapipe")
}

/// The `dermis` executable of this build, backtraces off (an error is one line).
pub fn dermis() -> std::process::Command {
    let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_dermis"));
    c.env("RUST_BACKTRACE", "0");
    c
}

/// An environment variable as a count, `default` when unset or not a number.
pub fn env_usize(key: &str, default: usize) -> usize {
    std::env::var(key)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Uploads a diffuse (RGBA, stored as half floats), linear-depth and skin-mask
/// input and runs the method's SSS passes alone on it (`Renderer::run_sss_only`):
/// the output and each pass's counts.
pub fn sss_only(
    r: &mut dermis::render::Renderer,
    diffuse: &[[f32; 4]],
    depth: &[f32],
    skin: &[bool],
) -> (Vec<[f32; 4]>, Vec<dermis::graph::PassSample>) {
    let f16: Vec<u16> = diffuse
        .iter()
        .flatten()
        .map(|&v| half::f16::from_f32(v).to_bits())
        .collect();
    r.upload_sss_inputs(&f16, depth, skin)
        .expect("uploading the SSS inputs");
    r.run_sss_only().expect("running the SSS passes")
}

/// The samples-passed count of the pass named `name`.
pub fn samples_passed(passes: &[dermis::graph::PassSample], name: &str) -> u64 {
    passes
        .iter()
        .find(|p| p.name == name)
        .unwrap_or_else(|| panic!("no pass {name}"))
        .samples_passed
}

/// Where failed image comparisons write their difference images:
/// target/test-diffs/ (beside CARGO_TARGET_TMPDIR, so a custom target folder
/// holds them too).
pub fn diff_dir() -> PathBuf {
    let tmp = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    tmp.parent().unwrap_or(&tmp).join("test-diffs")
}

/// A golden-image comparison's witness: if the test panics while it is alive
/// (an assertion on the two images failed), its drop writes
/// `target/test-diffs/NAME.png` (the image under test, the expected one and
/// their difference side by side) and prints the path. Declare it after the
/// two images and before the assertions on them; it costs nothing on success.
pub struct DiffOnFailure<'a> {
    pub name: String,
    pub width: usize,
    pub height: usize,
    pub got: &'a [[f32; 4]],
    pub want: &'a [[f32; 4]],
}

impl<'a> DiffOnFailure<'a> {
    pub fn new(
        name: impl Into<String>,
        width: usize,
        height: usize,
        got: &'a [[f32; 4]],
        want: &'a [[f32; 4]],
    ) -> Self {
        DiffOnFailure {
            name: name.into(),
            width,
            height,
            got,
            want,
        }
    }
}

impl Drop for DiffOnFailure<'_> {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            return;
        }
        match write_diff_image(&self.name, self.width, self.height, self.got, self.want) {
            Ok(p) => eprintln!("{}: difference image {}", self.name, p.display()),
            Err(e) => eprintln!("{}: writing the difference image failed: {e}", self.name),
        }
    }
}

/// Writes `diff_dir()/NAME.png`: three panels side by side, `got`, `want`
/// (linear RGB, clamped to 0..1, sRGB-encoded) and |got - want| per channel
/// scaled so the largest difference is white (that difference is printed).
/// Returns the path.
pub fn write_diff_image(
    name: &str,
    w: usize,
    h: usize,
    got: &[[f32; 4]],
    want: &[[f32; 4]],
) -> Result<PathBuf, String> {
    if got.len() != w * h || want.len() != w * h {
        return Err(format!(
            "sizes differ: {} and {} pixels for {w}x{h}",
            got.len(),
            want.len()
        ));
    }
    let diff: Vec<[f32; 3]> = got
        .iter()
        .zip(want)
        .map(|(a, b)| [0, 1, 2].map(|c| (a[c] - b[c]).abs()))
        .collect();
    let max = diff
        .iter()
        .flatten()
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0f32, f32::max);
    eprintln!("{name}: largest difference {max:.3e}");
    let srgb = |v: f32| {
        let v = if v.is_finite() {
            v.clamp(0.0, 1.0)
        } else {
            1.0
        };
        (v.powf(1.0 / 2.2) * 255.0 + 0.5) as u8
    };
    let mut img = image::RgbImage::new(3 * w as u32, h as u32);
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let d = diff[i].map(|v| if max > 0.0 { v / max } else { 0.0 });
            for (panel, px) in [
                [got[i][0], got[i][1], got[i][2]],
                [want[i][0], want[i][1], want[i][2]],
                d,
            ]
            .iter()
            .enumerate()
            {
                img.put_pixel((panel * w + x) as u32, y as u32, image::Rgb(px.map(srgb)));
            }
        }
    }
    let dir = diff_dir();
    std::fs::create_dir_all(&dir).map_err(|e| format!("creating {}: {e}", dir.display()))?;
    let path = dir.join(format!("{}.png", sanitize(name)));
    img.save(&path)
        .map_err(|e| format!("writing {}: {e}", path.display()))?;
    Ok(path)
}

/// A test name as a file name: letters, digits, '-' and '_' kept, the rest '_'.
fn sanitize(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// The gpu-allocator allocations `ctx` holds now.
pub fn live_allocations(ctx: &Context) -> usize {
    ctx.allocator().generate_report().allocations.len()
}

/// The creation steps a set-up sweep fails, for its `case`-th case (a
/// method, a path) of `steps`: every step of the first case; of the others,
/// every `DERMIS_TEARDOWN_STRIDE`-th (default 8), starting at `case` modulo
/// the stride, so the cases together still reach every offset. The cases
/// share the frame's own steps, which the first case covers whole. `.ci/run`
/// runs the sweeps again with a stride of 1 (docs/tests.md, "Longer runs").
pub fn sweep_steps(case: usize, steps: usize) -> impl Iterator<Item = usize> {
    let stride = if case == 0 {
        1
    } else {
        env_usize("DERMIS_TEARDOWN_STRIDE", 8).max(1)
    };
    (case % stride..steps).step_by(stride)
}

/// Makes the renderer's set-up for `settings` fail at each of its creation
/// steps in turn (`Context::fail_creation_after`): every failure must be one
/// error line naming the injected failure and must free its memory at once.
/// Leaves failure injection off; returns the number of steps. `what` names the
/// case in the messages.
pub fn fail_each_creation_step(
    ctx: &Context,
    scene: &dermis::scene::Scene,
    settings: &dermis::render::RenderSettings,
    what: &str,
) -> usize {
    use dermis::render::Renderer;
    let base = live_allocations(ctx);
    let before = ctx.creations();
    drop(Renderer::new(ctx, scene, settings).expect("a clean set-up"));
    let steps = ctx.creations() - before;
    for k in 0..steps {
        ctx.fail_creation_after(Some(k));
        let e = match Renderer::new(ctx, scene, settings) {
            Ok(_) => panic!("{what}: step {k} of {steps} did not fail"),
            Err(e) => format!("{e:#}"),
        };
        assert!(
            e.contains("injected failure") && !e.contains('\n'),
            "{what} step {k}: {e}"
        );
        assert_eq!(
            live_allocations(ctx),
            base,
            "{what} step {k} ({e}) left memory allocated"
        );
    }
    ctx.fail_creation_after(None);
    steps
}

/// Synthetic SSS inputs of `w` x `h` (diffuse RGBA with the strength in
/// alpha, linear depth, skin mask): a smooth image with sharp albedo steps
/// (where a filter's rounding shows), per-pixel strength, a depth step from
/// `depths[0]` to `depths[1]` below row 40 and a skin mask with a hole and a
/// separate island of 5 x 5 pixels centred on `island` (the frame need not
/// be a whole number of tiles).
pub fn synthetic_sss_inputs(
    w: usize,
    h: usize,
    island: (f32, f32),
    depths: [f32; 2],
) -> (Vec<[f32; 4]>, Vec<f32>, Vec<bool>) {
    let mut diffuse = Vec::with_capacity(w * h);
    let mut depth = Vec::with_capacity(w * h);
    let mut skin = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let (fx, fy) = (x as f32, y as f32);
            let step = if (x / 7 + y / 5) % 2 == 0 { 0.25 } else { 0.0 };
            let r = 0.45 + 0.30 * (fx / 6.0).sin() * (fy / 9.0).cos() + step;
            let g = 0.30 + 0.20 * (fx / 11.0 + fy / 7.0).cos() + step * 0.5;
            let b = 0.20 + 0.15 * (fy / 5.0).sin();
            let strength = if x < w / 3 { 1.0 } else { 0.7 };
            let (dx, dy) = (fx - 45.0, fy - 32.0);
            let face = dx * dx / (40.0 * 40.0) + dy * dy / (26.0 * 26.0) < 1.0;
            let hole = (fx - 30.0).abs() < 4.0 && (fy - 20.0).abs() < 3.0;
            let on_island = (fx - island.0).abs() < 3.0 && (fy - island.1).abs() < 3.0;
            let is_skin = (face && !hole) || on_island;
            diffuse.push(dermis::skin::texel::round_f16([
                r,
                g,
                b,
                if is_skin { strength } else { 0.0 },
            ]));
            depth.push(if y > 40 { depths[1] } else { depths[0] });
            skin.push(is_skin);
        }
    }
    (diffuse, depth, skin)
}
