//! Times the planner's inputs per frame (issue 16 item 6,
//! docs/plan-over-time.md "Plan time per frame"): a crowd of N walking one
//! head height toward the camera over 30 frames at 1280x720 on the Xbox 360
//! at 2 ms, re-planned every frame with the margin, from the per-frame
//! inputs (skin patches, price grid), against the exact inputs of
//! `dermis plan` for the same frames. With FILL set, the price grid is
//! filled at set-up (`FrameInputs::fill_scene`, as `dermis plan-motion`
//! does); without, it is priced lazily as the walk reaches new scales.
//!
//!   [FILL=1] cargo run --release --features tools --example plan_inputs_time [N ...]   (default 16 64 256)
use std::time::Instant;

use dermis::budget::profile::Profile;
use dermis::plan::frame_inputs::FrameInputs;
use dermis::plan::measured::Measured;
use dermis::plan::over_time::{replan, FrameInput, Replan, Walk, DEFAULT_MARGIN};
use dermis::plan::pipeline::{
    atlas_mm, characters, load_models, reference_model, setting_costs, NODE_LIMIT,
};
use dermis::render::RenderSettings;
use dermis::scene::gltf_load::TextureOverrides;

fn stats(xs: &[f64]) -> (f64, f64) {
    (
        xs.iter().sum::<f64>() / xs.len() as f64,
        xs.iter().copied().fold(0.0, f64::max),
    )
}

fn main() -> anyhow::Result<()> {
    let scene = dermis::scene::builtin_scene("face", &TextureOverrides::default(), None)?;
    let (models, _) = load_models()?;
    let refm = reference_model(&models)?;
    let prof = Profile::load("xbox360")?;
    let acc = Measured::load_default(Measured::asset_of(None))?;
    let atlas = atlas_mm(&scene);
    let counts: Vec<u32> = std::env::args()
        .skip(1)
        .map(|a| a.parse())
        .collect::<Result<_, _>>()?;
    let counts = if counts.is_empty() {
        vec![16, 64, 256]
    } else {
        counts
    };
    for heads in counts {
        let base = RenderSettings {
            heads,
            distance_heads: 3.0,
            ..RenderSettings::study()
        };
        let walk = Walk::new(30, 1.0)?;
        let mut per_frame = FrameInputs::new(&scene, &models, refm, &prof, base.width, base.height);
        if std::env::var_os("FILL").is_some() {
            per_frame.fill_scene();
        }
        let frames: Vec<FrameInput> = (0..walk.frames)
            .map(|k| {
                per_frame.frame(&RenderSettings {
                    walk_heads: walk.at(k),
                    ..base.clone()
                })
            })
            .collect();
        let plans = replan(
            &frames,
            &Replan {
                accuracy: &acc,
                budget_ms: 2.0,
                switch_margin: DEFAULT_MARGIN,
                node_limit: Some(NODE_LIMIT),
                look_ahead: 0,
            },
        );
        let inputs: Vec<f64> = frames.iter().map(|f| f.inputs_ms).collect();
        let costs: Vec<f64> = frames.iter().map(|f| f.costs_ms).collect();
        let solve: Vec<f64> = plans.iter().map(|p| p.solve_ms).collect();
        // The first frame fills the price grid from nothing; the frames after
        // it price only the scales the walk reaches.
        let ((im, ix), (cm, cx), (sm, sx)) =
            (stats(&inputs[1..]), stats(&costs[1..]), stats(&solve));
        // The exact inputs of two frames, for comparison.
        let mut exact = Vec::new();
        for k in [0, walk.frames - 1] {
            let s = RenderSettings {
                walk_heads: walk.at(k),
                ..base.clone()
            };
            let t = Instant::now();
            let chars = characters(&scene, &s, refm);
            let _ = setting_costs(&models, &chars, &prof, s.width, s.height, atlas);
            exact.push(t.elapsed().as_secs_f64() * 1e3);
        }
        println!(
            "{heads:>4} characters: set-up {:.1} ms; first frame's inputs {:.2} ms (pricing {:.2}); later frames' inputs mean {im:.2} ms (max {ix:.2}), of it pricing {cm:.2} ({cx:.2}); solve mean {sm:.2} ms (max {sx:.2}); grid points priced {}; exact inputs {:.1} ms",
            per_frame.setup_ms,
            inputs[0],
            costs[0],
            per_frame.priced(),
            exact.iter().sum::<f64>() / exact.len() as f64
        );
    }
    Ok(())
}
