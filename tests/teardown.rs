//! Teardown (issue 11): the validation layer listens until the device is
//! destroyed (`Context::finish`), so an object left undestroyed is an error
//! (VUID-vkDestroyDevice-device-00378), and the allocator names every memory
//! allocation left. Every method on success, and every error path after the
//! device opens, leave nothing: set-up is made to fail at each of its creation
//! steps in turn (`Context::fail_creation_after`), and the named error paths are
//! provoked directly (an option the device refuses, a ground truth without skin,
//! one too big for memory, a failed readback). lavapipe, validation on.
//!
//! The first method fails at every one of its creation steps (136 for
//! separable); the others, which share the frame's steps, at every fourth one,
//! each from its own offset (`common::sweep_steps`). DERMIS_TEARDOWN_STRIDE=1
//! tries every step of every method (`.ci/run` does; all clean, see
//! docs/reliability.md).

mod common;

use dermis::render::{RenderSettings, Renderer};
use dermis::run::{run, FrameCounts, RunOptions};
use dermis::scene::{default_scene, egg_scene, Scene};
use dermis::vk::context::Context;
use dermis::vk::memory::Buffer;
use dermis::vk::pipeline::Samplers;

fn small(method: &str) -> (Scene, RenderSettings) {
    let mut s = RenderSettings {
        width: 64,
        height: 36,
        shadow_size: 256,
        ..Default::default()
    }
    .with(common::m(method), &[]);
    if method == "reference" {
        s = s.with(common::m(method), &[("density", "4")]);
        (egg_scene(), s)
    } else {
        (default_scene(), s)
    }
}

fn live_allocations(ctx: &Context) -> usize {
    ctx.allocator().generate_report().allocations.len()
}

// The check itself: objects left at teardown are named, by the allocator
// (memory) and by the validation layer (every object).
#[test]
fn finish_names_what_was_left() {
    let ctx = common::ctx();
    let _forgotten = Buffer::new(
        &ctx,
        "forgotten buffer",
        64,
        ash::vk::BufferUsageFlags::UNIFORM_BUFFER,
        gpu_allocator_location(),
    )
    .unwrap();
    let _samplers = Samplers::new(&ctx).unwrap();
    let e = format!("{:#}", ctx.finish().unwrap_err());
    assert!(
        e.contains("'forgotten buffer'") && e.contains("never freed"),
        "{e}"
    );
    assert!(e.contains("VUID-vkDestroyDevice-device-00378"), "{e}");
    assert!(e.contains("has not been destroyed"), "{e}");
    // Five samplers and the buffer.
    assert!(e.matches("has not been destroyed").count() >= 6, "{e}");
}

fn gpu_allocator_location() -> gpu_allocator::MemoryLocation {
    gpu_allocator::MemoryLocation::CpuToGpu
}

// Every method renders (frames and a capture) and tears down clean.
#[test]
fn every_method_tears_down_clean() {
    for m in dermis::method::METHODS {
        let ctx = common::ctx();
        let (scene, settings) = small(m.name);
        let opts = RunOptions {
            frames: FrameCounts::new(1, 2).unwrap(),
            ..RunOptions::capture_once("teardown")
        };
        run(&ctx, &scene, &settings, &opts).unwrap_or_else(|e| panic!("{}: {e:#}", m.name));
        ctx.finish()
            .unwrap_or_else(|e| panic!("{}: teardown: {e:#}", m.name));
    }
}

// Set-up fails at every creation step in turn; each failure is one error,
// frees its memory at once, and the device tears down clean after all of them.
// Long because the failures are provoked method by method.
#[test]
fn every_setup_failure_tears_down_clean() {
    let t = std::time::Instant::now();
    let mut total = 0;
    for (i, m) in dermis::method::METHODS.iter().enumerate() {
        let ctx = common::ctx();
        let (scene, settings) = small(m.name);
        let base = live_allocations(&ctx);
        let before = ctx.creations();
        drop(Renderer::new(&ctx, &scene, &settings).expect("a clean set-up"));
        let steps = ctx.creations() - before;
        let mut tried = 0;
        for k in common::sweep_steps(i, steps) {
            ctx.fail_creation_after(Some(k));
            let e = match Renderer::new(&ctx, &scene, &settings) {
                Ok(_) => panic!("{}: step {k} of {steps} did not fail", m.name),
                Err(e) => format!("{e:#}"),
            };
            assert!(
                e.contains("injected failure") && !e.contains('\n'),
                "{} step {k}: {e}",
                m.name
            );
            assert_eq!(
                live_allocations(&ctx),
                base,
                "{} step {k} ({e}) left memory allocated",
                m.name
            );
            ctx.check_validation(&format!("after {}'s set-up failed at step {k}", m.name))
                .unwrap();
            tried += 1;
        }
        ctx.fail_creation_after(None);
        ctx.finish()
            .unwrap_or_else(|e| panic!("{}: teardown after {tried} failures: {e:#}", m.name));
        eprintln!(
            "{}: {steps} creation steps, {tried} failed in turn, clean",
            m.name
        );
        total += tried;
    }
    eprintln!(
        "{total} failed set-ups in {:.1} s",
        t.elapsed().as_secs_f64()
    );
}

// The error paths a user meets after the device opens, and a failure during a
// capture (a readback buffer that cannot be made).
#[test]
fn named_error_paths_tear_down_clean() {
    let ctx = common::ctx();
    let max = ctx.facts.max_image_dimension_2d;
    // An option only the open device refuses.
    let (scene, mut s) = small("separable");
    s.width = max + 1;
    let e = format!("{:#}", Renderer::new(&ctx, &scene, &s).err().unwrap());
    assert!(e.contains("exceeds"), "{e}");
    // A ground truth of a scene without skin.
    let (mut no_skin, s) = small("reference");
    no_skin.head.material.skin = false;
    if let Some(b) = no_skin.backdrop.as_mut() {
        b.material.skin = false;
    }
    let e = format!("{:#}", Renderer::new(&ctx, &no_skin, &s).err().unwrap());
    assert!(e.contains("no skin surface"), "{e}");
    // A ground truth too big for the device.
    let (scene, mut s) = small("reference");
    s = s.with(common::m("reference"), &[("density", "256")]);
    s.heads = 64;
    let e = format!("{:#}", Renderer::new(&ctx, &scene, &s).err().unwrap());
    assert!(e.contains("more than this device holds"), "{e}");
    // A readback that fails in the middle of a capture.
    let (scene, s) = small("separable");
    let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
    let base = live_allocations(&ctx);
    ctx.fail_creation_after(Some(1));
    let e = format!("{:#}", r.capture(true).err().unwrap());
    assert!(e.contains("injected failure"), "{e}");
    assert_eq!(
        live_allocations(&ctx),
        base,
        "the failed capture left memory"
    );
    // The renderer still works after it.
    r.capture(false).unwrap();
    drop(r);
    ctx.finish().unwrap();
}
