//! Soak (issue 11): many frames of every method, and many renders in one
//! process (what `eval` does), on lavapipe with validation on. Resident memory
//! and the live memory allocations stay flat, no Vulkan object is created per
//! frame, and the device tears down clean at the end (`Context::finish`: any
//! object left undestroyed is named by VUID-vkDestroyDevice-device-00378).
//!
//! Before issue 11's fix lavapipe leaked a compiled shader per material bind of
//! the geometry pass: 2.5 MB a frame, so the 120 frames below grew by 300 MB.
//!
//! Default (the short soak of `cargo test`): 64x36, per method 20 warm-up
//! frames, then 40 frames (the reference: 3 and 4, at 4 samples per mm^2;
//! the texture-space methods with 256-texel maps, 4x faster); 4
//! renders of 2 frames each in a row. Bounds: the highest resident memory so far
//! grows at most QUARTER_BOUND_MIB in at least STEADY_QUARTERS of the four quarters of the
//! frames and at most TOTAL_BOUND_MIB in all but its largest quarter's step (a leak grows in
//! every quarter; a driver cache or a new malloc arena of a rasteriser thread, once: lavapipe
//! takes a 12-14 MiB step at a random frame in about one run of three, once 58 MiB in
//! texture space's first quarter, and in some runs the allocator's first 2.5 MiB swing sets
//! a high in another quarter); after the renders, at most
//! TOTAL_BOUND_MIB above the value after the first; live allocations exactly
//! equal; 0 objects created by the frame loop; 0 messages at teardown. A quarter
//! of the short soak is 10 frames, so it fails on any leak of 100 KiB a frame or
//! more (the fixed one leaked 2.5 MB a frame: 25 MB a quarter); the live
//! allocations and created objects are counted exactly whatever the length.
//!
//! DERMIS_SOAK=1 runs the soak CI ran before it was shortened (120 frames a
//! method, the reference 12; 8 renders: a leak of 34 KiB a frame). Long run
//! (the figures in docs/reliability.md):
//!     DERMIS_SOAK_FRAMES=10000 DERMIS_SOAK_RENDERS=100 cargo test --release --test soak -- --nocapture
//! DERMIS_SOAK_VALIDATE=0 runs without the validation layer (about 3x faster);
//! DERMIS_SOAK_METHODS=separable,none limits the methods.

mod common;

use dermis::render::{RenderSettings, Renderer};
use dermis::run::{run, FrameCounts, RunOptions};
use dermis::scene::{default_scene, egg_scene, Scene};
use dermis::vk::context::{Context, ContextDesc, DeviceChoice};

/// Most resident-memory growth in a quarter of the frames, in MiB, in three
/// quarters of four (the fixed leak: 75 MB a quarter of 120 frames).
const QUARTER_BOUND_MIB: f64 = 1.0;
/// Most growth over all the frames but their largest quarter's step (and over the
/// renders), in MiB.
const TOTAL_BOUND_MIB: f64 = 24.0;
/// Quarters (of four) that must stay within QUARTER_BOUND_MIB. Two one-off
/// events can each set a high in a quarter of their own (the arena step and
/// the first of the allocator's 2.5 MiB swings: seen together in 3 of 5 runs
/// of one branch, 2026-12-02), while a leak sets one in all four, so two
/// steady quarters still fail every leak the bound can see.
const STEADY_QUARTERS: usize = 2;
/// Frames a method runs before its resident memory is first read: the
/// allocator's first arena steps and the driver's caches come in these.
const WARMUP_FRAMES: usize = 20;

/// The soak's length: (frames a method, renders in a row). The short soak
/// unless DERMIS_SOAK=1 asks for the long one; DERMIS_SOAK_FRAMES and
/// DERMIS_SOAK_RENDERS override either.
fn length() -> (usize, usize) {
    let long = std::env::var("DERMIS_SOAK").is_ok_and(|v| v == "1");
    // The short soak is the test command's (issue 27: its time is a budget);
    // CI runs the long one too (.ci/run).
    let (frames, renders) = if long { (120, 8) } else { (40, 4) };
    (
        common::env_usize("DERMIS_SOAK_FRAMES", frames),
        common::env_usize("DERMIS_SOAK_RENDERS", renders),
    )
}

/// Resident set size of this process in MiB (/proc/self/statm).
fn rss_mib() -> f64 {
    let statm = std::fs::read_to_string("/proc/self/statm").expect("/proc/self/statm");
    let pages: f64 = statm
        .split_whitespace()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .expect("resident pages");
    pages * 4096.0 / (1024.0 * 1024.0)
}

/// Live memory allocations (count, bytes) of the context's allocator.
fn live(ctx: &Context) -> (usize, u64) {
    let r = ctx.allocator().generate_report();
    (r.allocations.len(), r.total_allocated_bytes)
}

fn context() -> Context {
    if std::env::var("DERMIS_SOAK_VALIDATE").as_deref() == Ok("0") {
        let name = std::env::var("DERMIS_TEST_DEVICE").unwrap_or_else(|_| "llvmpipe".into());
        return Context::new(&ContextDesc {
            device: DeviceChoice::Name(name),
            validate: false,
            count_fetches: false,
        })
        .expect("a Vulkan context on lavapipe");
    }
    common::ctx()
}

/// The scene and settings a method soaks with: the ground truth on the egg at a
/// low density (its samples dominate memory otherwise), the rest on the face.
fn setup(method: &str) -> (Scene, RenderSettings) {
    let mut s = RenderSettings {
        width: 64,
        height: 36,
        shadow_size: 256,
        ..RenderSettings::study()
    }
    .with(common::m(method), &[]);
    // The texture-space maps at 256 texels in the short soak: at their
    // default 2048 lavapipe draws tsd at under a frame a second, three
    // quarters of the soak's time, while a leak per frame is one at any map
    // size (the long soak, DERMIS_SOAK=1, keeps the default).
    let long = std::env::var("DERMIS_SOAK").is_ok_and(|v| v == "1");
    if method.starts_with("tsd") && !long {
        s = s.with(common::m(method), &[("irradiance-size", "256")]);
    }
    if method == "reference" {
        s = s.with(common::m(method), &[("density", "4")]);
        (egg_scene(), s)
    } else {
        (default_scene(), s)
    }
}

fn methods() -> Vec<String> {
    match std::env::var("DERMIS_SOAK_METHODS") {
        Ok(list) => list.split(',').map(str::to_string).collect(),
        Err(_) => dermis::method::METHODS
            .iter()
            .map(|m| m.name.to_string())
            .collect(),
    }
}

// One test: resident memory is per process, so nothing may run beside it.
#[test]
fn frames_and_renders_stay_flat() {
    let (frames, renders) = length();
    let ctx = context();
    let mut failures = Vec::new();
    eprintln!(
        "soak: 64x36, validation {}; RSS bounds: {QUARTER_BOUND_MIB} MiB in {STEADY_QUARTERS} of 4 quarters, {TOTAL_BOUND_MIB} MiB in all",
        ctx.validation
    );
    eprintln!(
        "  {:<12} {:>6} {:>9} {:>9} {:>10} {:>24} {:>7} {:>8}",
        "method",
        "frames",
        "RSS MiB",
        "growth",
        "KiB/frame",
        "by quarter (MiB)",
        "allocs",
        "created"
    );
    for method in methods() {
        let (scene, settings) = setup(&method);
        let (warm, n) = if method == "reference" {
            (3, (frames / 10).max(1))
        } else {
            (WARMUP_FRAMES, frames)
        };
        let mut r = Renderer::new(&ctx, &scene, &settings).expect("renderer");
        r.run_frames(warm, |_| {}).expect("warm-up frames");
        let (rss0, live0, made0) = (rss_mib(), live(&ctx), ctx.creations());
        let t = std::time::Instant::now();
        let mut rss = vec![rss0];
        for q in 0..4 {
            let frames = (n * (q + 1)) / 4 - (n * q) / 4;
            r.run_frames(frames, |_| {}).expect("frames");
            rss.push(rss_mib());
        }
        let (rss1, live1, made1) = (rss_mib(), live(&ctx), ctx.creations());
        let growth = rss1 - rss0;
        let quarters: Vec<f64> = rss.windows(2).map(|w| w[1] - w[0]).collect();
        // A leak sets a new high every quarter; the allocator handing a few MiB
        // back and forth (measured: -2.5, +2.5, -2.5, +2.5 MiB over four quarters
        // of ss-jittered, net 0) or one arena step sets at most one. So what each
        // quarter adds to the highest resident memory so far is bounded.
        let highs: Vec<f64> = rss
            .iter()
            .scan(f64::MIN, |hi, &r| {
                *hi = hi.max(r);
                Some(*hi)
            })
            .collect();
        let steady = highs
            .windows(2)
            .filter(|w| w[1] - w[0] <= QUARTER_BOUND_MIB)
            .count();
        eprintln!(
            "  {method:<12} {n:>6} {rss1:>9.1} {growth:>+9.2} {:>10.2} {:>24} {:>7} {:>8}   ({:.1} frames/s)",
            growth * 1024.0 / n as f64,
            quarters
                .iter()
                .map(|g| format!("{g:+.1}"))
                .collect::<Vec<_>>()
                .join(" "),
            live1.0,
            made1 - made0,
            n as f64 / t.elapsed().as_secs_f64()
        );
        // One step is the arena's (above); the rest is bounded.
        let largest_step = highs.windows(2).map(|w| w[1] - w[0]).fold(0.0f64, f64::max);
        if steady < STEADY_QUARTERS || growth - largest_step > TOTAL_BOUND_MIB {
            failures.push(format!(
                "{method}: resident memory grew {growth:.1} MiB over {n} frames ({quarters:.2?} MiB by quarter)"
            ));
        }
        if live1 != live0 {
            failures.push(format!(
                "{method}: live allocations went from {live0:?} to {live1:?}"
            ));
        }
        if made1 != made0 {
            failures.push(format!(
                "{method}: the frame loop created {} objects",
                made1 - made0
            ));
        }
        drop(r);
        ctx.check_validation(&format!("soaking {method}"))
            .unwrap_or_else(|e| failures.push(format!("{e:#}")));
    }

    // Renders in a row, each with its own renderer (eval's pattern).
    let (scene, settings) = setup("separable");
    let opts = RunOptions {
        frames: FrameCounts::new(0, 2).unwrap(),
        ..RunOptions::capture_once("soak")
    };
    let base = live(&ctx);
    let mut rss_first = 0.0;
    let t = std::time::Instant::now();
    for i in 0..renders {
        run(&ctx, &scene, &settings, &opts).expect("render");
        if live(&ctx) != base {
            failures.push(format!(
                "render {i}: live allocations {:?}, before {base:?}",
                live(&ctx)
            ));
        }
        if i == 0 {
            rss_first = rss_mib();
        }
    }
    let growth = rss_mib() - rss_first;
    eprintln!(
        "  {renders} renders of 2 frames in one process: RSS {:.1} MiB, {growth:+.2} MiB after the first ({:.1} s)",
        rss_mib(),
        t.elapsed().as_secs_f64()
    );
    if growth > TOTAL_BOUND_MIB {
        failures.push(format!(
            "{renders} renders: resident memory grew {growth:.1} MiB"
        ));
    }
    match ctx.finish() {
        Ok(()) => eprintln!("  teardown: 0 validation messages, 0 leaked allocations"),
        Err(e) => failures.push(format!("teardown: {e:#}")),
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
