//! Table 4.4's shape, modelled (docs/tsd.md, "Table 4.4's shape, modelled"):
//! every method of the table at 1, 5 and 16 characters (the crowd at 4 head
//! heights, 1280x720, 1024 maps), the counts from a run of the frame with the
//! fetch-counting build, priced by the budget model (fitted parameters) on the
//! 8600M GS (the table's GPU), the Xbox 360 and the H200. Prints the markdown
//! table; heavy on lavapipe (about two minutes).
//!
//! ```sh
//! cargo run --release --features tools --example table44_modelled -- [HEAD.glb] [DEVICE]
//! ```
//! HEAD defaults to the Lee Perry-Smith head beside the project, DEVICE (a
//! name substring) to llvmpipe. It was `tests/tsd_gpu.rs`'s ignored
//! `table_4_4_shape_modelled`: it only prints, so it is a program, not a test.

use std::path::PathBuf;

use anyhow::{Context as _, Result};
use dermis::app::budget::{method_frame, BudgetOptions};
use dermis::budget::profile::Profile;
use dermis::budget::{price_frame, ParamSet, Rescale};
use dermis::method::lookup;
use dermis::render::{FrameRequest, RenderSettings};
use dermis::vk::context::{Context, ContextDesc, DeviceChoice};

/// The table's rows: the methods Table 4.4 compares, as dermis names them.
const ROWS: [&str; 6] = ["none", "ss-jittered", "ssg", "separable", "tsd", "tsd-opt"];

fn main() -> Result<()> {
    let mut args = std::env::args().skip(1);
    let head = args.next().map_or_else(
        || PathBuf::from(dermis::app::eval::DEFAULT_HEAD),
        PathBuf::from,
    );
    let device = args.next().unwrap_or_else(|| "llvmpipe".into());
    let scene = dermis::scene::load_gltf_scene(&head, &Default::default(), None)
        .with_context(|| format!("loading the head {}", head.display()))?;
    let ctx_of = |count_fetches| {
        Context::new(&ContextDesc {
            device: DeviceChoice::Name(device.clone()),
            validate: false,
            count_fetches,
        })
    };
    let (ctx, counting) = (ctx_of(false)?, ctx_of(true)?);
    let profiles = ["geforce-8600m-gs", "xbox360", "nvidia-h200"]
        .map(Profile::load)
        .into_iter()
        .collect::<Result<Vec<_>>>()?;
    println!(
        "| method | heads | {} |",
        profiles
            .iter()
            .map(|p| format!("{} ms", p.profile.name))
            .collect::<Vec<_>>()
            .join(" | ")
    );
    for m in ROWS {
        for heads in [1, 5, 16] {
            let opts: &[(&str, &str)] = if m.starts_with("tsd") {
                &[("irradiance-size", "1024")]
            } else {
                &[]
            };
            let mut s = RenderSettings {
                width: 1280,
                height: 720,
                shadow_size: 256,
                distance_heads: 4.0,
                ..RenderSettings::study()
            }
            .with(lookup(m)?, opts);
            s.heads = heads;
            let budget = BudgetOptions {
                profiles: Vec::new(),
                out: std::env::temp_dir(),
                frames: dermis::run::FrameCounts::ONE,
                rescale: Rescale::AsRun,
                count_fetches: true,
                print: false,
                command: m.to_string(),
            };
            let frame = FrameRequest::new(&scene, s)?;
            let frame = method_frame(&ctx, Some(&counting), &frame, &budget)
                .with_context(|| format!("{m}, {heads} heads"))?;
            let ms: Vec<String> = profiles
                .iter()
                .map(|p| {
                    let b = price_frame(p, &frame, &ParamSet::fitted(), Rescale::AsRun);
                    format!("{:.2}", b.total_ms)
                })
                .collect();
            println!("| {m} | {heads} | {} |", ms.join(" | "));
        }
    }
    counting.finish()?;
    ctx.finish()
}
