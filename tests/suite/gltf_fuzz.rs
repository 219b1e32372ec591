//! glTF fuzzer: a fixed-seed mutation run over the Lee Perry-Smith head and over
//! generated files (accessor storage and layout, node graphs with cycles and deep
//! chains, primitive modes, buffer and image URIs, GLB containers, non-finite values).
//! Every case must end in a loaded scene or one clean error line: a panic, a hang or a
//! multi-line error fails the test. A few loaded cases are then rendered on lavapipe
//! at 64x36 with validation on, and must give finite output.
//!
//! Quick run (the default: 3000 random cases plus the fixed ones, up to 40 loaded cases
//! per category rendered; well under a minute in the debug profile):
//!     cargo test --test suite gltf_fuzz -- --nocapture
//! Long run (the number of random cases, and another seed):
//!     DERMIS_FUZZ_ITERS=50000 DERMIS_FUZZ_SEED=7 cargo test --release --test suite gltf_fuzz -- --nocapture
//! DERMIS_FUZZ_RENDER=0 skips the rendering part (no Vulkan needed).

use crate::common;
use dermis::scene::gltf_load::fixture::TempDir;

use dermis::render::RenderSettings;
use dermis::run::{run, FrameCounts, RunOptions};
use dermis::scene::gltf_load::fixture::{glb_bytes, Container};
use dermis::scene::gltf_load::{load_head_with_warnings, TextureOverrides};
use dermis::scene::load_gltf_scene;
use dermis::scene::mesh::Object;
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// A case taking longer than this is a hang.
const CASE_TIMEOUT: Duration = Duration::from_secs(60);
/// A clean error is one line of at most this many characters.
const MAX_ERROR_LEN: usize = 600;
/// Loaded cases rendered per category.
const RENDER_PER_CATEGORY: usize = 40;

#[path = "gltf_fuzz/mutate.rs"]
mod mutate;

use mutate::*;

// ---- Running cases ------------------------------------------------------------------------

enum Outcome {
    Loaded(Box<Object>),
    Error(String),
    Panic(String),
    Hang,
}

/// Loads a file on its own thread (default 2 MiB stack, so recursion shows) under
/// catch_unwind, giving up after CASE_TIMEOUT.
fn load(path: &Path) -> Outcome {
    let p = path.to_path_buf();
    let (tx, rx) = mpsc::channel();
    let spawned = std::thread::Builder::new()
        .name("fuzz-load".into())
        .spawn(move || {
            let r = std::panic::catch_unwind(|| {
                load_head_with_warnings(&p, &TextureOverrides::default())
            });
            let _ = tx.send(match r {
                Ok(Ok((obj, _warnings))) => Outcome::Loaded(Box::new(obj)),
                Ok(Err(e)) => Outcome::Error(format!("{e:#}")),
                Err(p) => Outcome::Panic(
                    p.downcast_ref::<String>()
                        .cloned()
                        .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                        .unwrap_or_default(),
                ),
            });
        });
    if spawned.is_err() {
        return Outcome::Panic("could not spawn the loader thread".into());
    }
    rx.recv_timeout(CASE_TIMEOUT).unwrap_or(Outcome::Hang)
}

/// A loaded object must be something the renderer can take.
fn check_loaded(obj: &Object) -> Result<(), String> {
    obj.mesh
        .validate()
        .map_err(|e| format!("loaded an invalid mesh: {e:#}"))?;
    for (i, v) in obj.mesh.vertices.iter().enumerate() {
        let all = v
            .position
            .iter()
            .chain(&v.normal)
            .chain(&v.uv)
            .chain(&v.tangent);
        if !all.clone().all(|c| c.is_finite()) {
            return Err(format!("loaded vertex {i} is not finite: {v:?}"));
        }
    }
    Ok(())
}

#[derive(Default)]
struct Tally {
    tried: usize,
    loaded: usize,
    errors: usize,
    samples: Vec<String>,
}

struct Fuzz {
    tally: BTreeMap<&'static str, Tally>,
    failures: Vec<String>,
    /// Loaded cases kept for rendering: (category, path).
    renderable: Vec<(&'static str, PathBuf)>,
}

impl Fuzz {
    fn case(&mut self, category: &'static str, path: &Path, what: &str) {
        let t = self.tally.entry(category).or_default();
        t.tried += 1;
        match load(path) {
            Outcome::Loaded(obj) => {
                t.loaded += 1;
                if let Err(e) = check_loaded(&obj) {
                    self.failures.push(format!("[{category}] {what}: {e}"));
                }
                if self
                    .renderable
                    .iter()
                    .filter(|(c, _)| *c == category)
                    .count()
                    < RENDER_PER_CATEGORY
                {
                    self.renderable.push((category, path.to_path_buf()));
                }
            }
            Outcome::Error(e) => {
                t.errors += 1;
                if e.contains('\n') || e.is_empty() || e.len() > MAX_ERROR_LEN {
                    self.failures.push(format!(
                        "[{category}] {what}: not one clean line ({} chars): {e:?}",
                        e.len()
                    ));
                }
                if t.samples.len() < 3
                    && !t
                        .samples
                        .iter()
                        .any(|s| s[..20.min(s.len())] == e[..20.min(e.len())])
                {
                    t.samples.push(e);
                }
            }
            Outcome::Panic(p) => self
                .failures
                .push(format!("[{category}] {what}: PANIC {p}")),
            Outcome::Hang => self.failures.push(format!(
                "[{category}] {what}: no result within {CASE_TIMEOUT:?}"
            )),
        }
    }
}

/// The one place the renderer is called, so a renamed API is adapted here only.
/// Returns the diffuse light and the 8-bit frame.
fn render_small(
    ctx: &dermis::vk::context::Context,
    scene: &dermis::scene::Scene,
) -> anyhow::Result<(Vec<[f32; 4]>, Vec<u8>)> {
    let settings = RenderSettings {
        width: 64,
        height: 36,
        shadow_size: 256,
        ..RenderSettings::study()
    };
    let opts = RunOptions {
        frames: FrameCounts::new(0, 1).unwrap(),
        capture: true,
        dump: false,
        ceilings: false,
        command: "fuzz".into(),
        progress: false,
    };
    let out = run(ctx, scene, &settings, &opts)?;
    let cap = out.capture.ok_or_else(|| anyhow::anyhow!("no capture"))?;
    ctx.check_validation("after the fuzz render")?;
    Ok((cap.diffuse, cap.ldr))
}

fn temp_dir() -> TempDir {
    dermis::scene::gltf_load::fixture::temp_dir("gltf-fuzz")
}

fn env_usize(key: &str, default: usize) -> usize {
    std::env::var(key)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

#[test]
fn gltf_fuzz() {
    let start = Instant::now();
    let iters = env_usize("DERMIS_FUZZ_ITERS", 3000);
    let seed = env_usize("DERMIS_FUZZ_SEED", 1) as u64;
    let mut rng = Rng(seed);
    let dir = temp_dir();
    let mut fz = Fuzz {
        tally: BTreeMap::new(),
        failures: Vec::new(),
        renderable: Vec::new(),
    };

    // Fixed cases first: the clean base in every container, then the random run.
    for (k, c) in [Container::DataUri, Container::BinFile, Container::Glb]
        .into_iter()
        .enumerate()
    {
        let m = base_model(&mut rng);
        let p = m.write(c, &dir, &format!("base{k}"));
        fz.case("base", &p, "clean base model");
    }
    // A FIFO as a buffer: opening it would block forever.
    let fifo = dir.join("fifo.bin");
    if std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success())
    {
        let mut m = base_model(&mut rng);
        m.json["buffers"][0]["uri"] = json!("fifo.bin");
        let p = m.write(Container::DataUri, &dir, "fifo");
        fz.case("uri", &p, "FIFO buffer");
    }

    // The head: byte flips and JSON mutations of the real file, in its own directory
    // (no textures beside it, so the cases stay fast).
    let lps = common::lps_path();
    let lps_dir = dir.join("lps");
    std::fs::create_dir_all(&lps_dir).expect("lps dir");
    let lps_bytes = lps
        .as_ref()
        .map(|p| std::fs::read(p).expect("read LeePerrySmith.glb"));
    let lps_parts = lps_bytes.as_ref().map(|b| {
        let jl = u32::from_le_bytes([b[12], b[13], b[14], b[15]]) as usize;
        let json: Value = serde_json::from_slice(&b[20..20 + jl]).expect("LPS JSON");
        let bin = b[20 + jl + 8..].to_vec();
        (json, bin)
    });
    if let Some(b) = &lps_bytes {
        let p = lps_dir.join("clean.glb");
        std::fs::write(&p, b).expect("write");
        fz.case("lps", &p, "clean head");
    } else {
        eprintln!("LeePerrySmith.glb not found: the head part of the fuzz is skipped");
    }

    for i in 0..iters {
        let category: &'static str = match i % 9 {
            0 => "accessor",
            1 => "quantized",
            2 => "nodes",
            3 => "modes",
            4 => "uri",
            5 => "glb",
            6 => "values",
            7 => "json",
            _ => "lps",
        };
        let name = format!("{category}{i}");
        let mut m = base_model(&mut rng);
        let container = rng.pick(&[Container::DataUri, Container::BinFile, Container::Glb]);
        let (path, what) = match category {
            "accessor" => {
                let w = mutate_accessors(&mut m, &mut rng);
                (m.write(container, &dir, &name), w)
            }
            "quantized" => {
                let w = quantized(&mut m, &mut rng);
                (m.write(container, &dir, &name), w)
            }
            "nodes" => {
                let w = mutate_nodes(&mut m, &mut rng);
                (m.write(container, &dir, &name), w)
            }
            "modes" => {
                let w = mutate_mode(&mut m, &mut rng);
                (m.write(container, &dir, &name), w)
            }
            "uri" => {
                let w = mutate_uri(&mut m, &mut rng, &dir, &name);
                let c = if container == Container::Glb {
                    Container::DataUri
                } else {
                    container
                };
                (m.write(c, &dir, &name), w)
            }
            "glb" => {
                let (bytes, w) = corrupt_glb(&m, &mut rng);
                let p = dir.join(format!("{name}.glb"));
                std::fs::write(&p, bytes).expect("write");
                (p, w)
            }
            "values" => {
                let w = mutate_values(&mut m, &mut rng);
                (m.write(container, &dir, &name), w)
            }
            "json" => {
                let k = 1 + rng.below(3);
                let w: Vec<String> = (0..k).map(|_| mutate_json(&mut m.json, &mut rng)).collect();
                (m.write(container, &dir, &name), w.join("; "))
            }
            _ => {
                let (Some(bytes), Some((json, bin))) = (&lps_bytes, &lps_parts) else {
                    continue;
                };
                let p = lps_dir.join(format!("{name}.glb"));
                if rng.chance(0.5) {
                    let mut b = bytes.clone();
                    let k = 1 + rng.below(8);
                    for _ in 0..k {
                        let at = rng.below(b.len());
                        b[at] ^= 1 << rng.below(8);
                    }
                    std::fs::write(&p, b).expect("write");
                    (p, format!("{k} bit flips"))
                } else {
                    let mut j = json.clone();
                    let k = 1 + rng.below(3);
                    let w: Vec<String> = (0..k).map(|_| mutate_json(&mut j, &mut rng)).collect();
                    std::fs::write(&p, glb_bytes(&j, Some(bin))).expect("write");
                    (p, w.join("; "))
                }
            }
        };
        fz.case(category, &path, &what);
    }
    let load_time = start.elapsed();

    // Figures.
    let (mut tried, mut loaded, mut errors) = (0, 0, 0);
    eprintln!("glTF fuzz, seed {seed}, {iters} random cases:");
    eprintln!(
        "  {:<10} {:>6} {:>7} {:>7}",
        "category", "tried", "loaded", "errors"
    );
    for (c, t) in &fz.tally {
        eprintln!("  {c:<10} {:>6} {:>7} {:>7}", t.tried, t.loaded, t.errors);
        tried += t.tried;
        loaded += t.loaded;
        errors += t.errors;
    }
    eprintln!(
        "  {:<10} {tried:>6} {loaded:>7} {errors:>7}   (loading took {load_time:.1?})",
        "all"
    );
    for (c, t) in &fz.tally {
        for s in &t.samples {
            eprintln!("  e.g. [{c}] {s}");
        }
    }

    // Render one loaded case per category through the real renderer.
    if std::env::var("DERMIS_FUZZ_RENDER").as_deref() != Ok("0") && fz.failures.is_empty() {
        let ctx = common::ctx();
        let t0 = Instant::now();
        let (mut rendered, mut with_skin, mut unframed) = (0, 0, 0);
        for (category, path) in &fz.renderable {
            let scene = match load_gltf_scene(path, &TextureOverrides::default(), None) {
                Ok(s) => s,
                Err(e) => {
                    let e = format!("{e:#}");
                    if e.contains('\n') {
                        fz.failures
                            .push(format!("[{category}] scene: not one line: {e:?}"));
                    }
                    if unframed < 3 {
                        eprintln!("  [{category}] not rendered: {e}");
                    }
                    unframed += 1;
                    continue;
                }
            };
            match render_small(&ctx, &scene) {
                Ok((diffuse, ldr)) => {
                    rendered += 1;
                    // Alpha of the diffuse light is the SSS strength: > 0 where skin
                    // was drawn. The clean head must show it (the generated grids are
                    // no heads: the framing may look at them edge-on).
                    let skin = diffuse.iter().filter(|p| p[3] > 0.0).count();
                    if skin > 0 {
                        with_skin += 1;
                    } else if path.ends_with("lps/clean.glb") {
                        fz.failures.push(format!(
                            "[{category}] {}: no skin in the frame",
                            path.display()
                        ));
                    }
                    if diffuse.iter().flatten().any(|v| !v.is_finite()) {
                        fz.failures.push(format!(
                            "[{category}] {}: non-finite diffuse light",
                            path.display()
                        ));
                    }
                    if ldr.len() != 64 * 36 * 4 {
                        fz.failures.push(format!(
                            "[{category}] {}: frame has {} bytes",
                            path.display(),
                            ldr.len()
                        ));
                    }
                }
                Err(e) => fz.failures.push(format!(
                    "[{category}] {}: render failed: {e:#}",
                    path.display()
                )),
            }
        }
        eprintln!(
            "  rendered {rendered} loaded cases at 64x36 ({with_skin} show skin) in {:.1?}; {unframed} loaded but not framed (mm_per_unit)",
            t0.elapsed()
        );
    }
    eprintln!("  total {:.1?}", start.elapsed());
    // Failing cases stay on disk to be reproduced.
    if fz.failures.is_empty() {
        let _ = std::fs::remove_dir_all(&dir);
    } else {
        eprintln!("  the failing cases are kept in {}", dir.display());
    }
    assert!(
        fz.failures.is_empty(),
        "{} failures:\n{}",
        fz.failures.len(),
        fz.failures.join("\n")
    );
    assert!(
        loaded > 0 && errors > 0,
        "the run should both load and refuse files"
    );
}
