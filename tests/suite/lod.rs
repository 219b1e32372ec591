//! Levels of detail (issue 29, `--lod-pixels`): a crowd drawn with each
//! character's coarsest level whose measured error covers at most the given
//! pixels, on lavapipe with validation on. Fewer triangles reach the shadow
//! map and the geometry pass; the frame stays within a stated distance of
//! the full meshes' (the error the levels add, measured here and in
//! docs/perf/issue29).

use crate::common;

use dermis::render::{RenderSettings, Renderer};

/// The error budget of the test (pixels).
const LOD_PX: f32 = 1.0;

fn settings(lod_pixels: f32) -> RenderSettings {
    RenderSettings {
        width: 320,
        height: 180,
        heads: 16,
        lod_pixels,
        ..RenderSettings::study()
    }
}

/// Triangles each pass declared, from a `render` run's report.
fn triangles(lod: &str) -> (u64, u64) {
    let dir = tempfile::tempdir().unwrap();
    let out = common::dermis()
        .args([
            "render", "--heads", "16", "--width", "320", "--height", "180",
        ])
        .args([
            "--frames",
            "1",
            "--warmup",
            "0",
            "--lod-pixels",
            lod,
            "--out",
        ])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("report.json")).unwrap()).unwrap();
    let of = |name: &str| {
        r["passes"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["name"] == name)
            .and_then(|p| p["work"]["triangles"].as_u64())
            .unwrap()
    };
    (of("shadow map"), of("geometry"))
}

#[test]
fn a_crowd_draws_fewer_triangles_within_a_stated_error() {
    let (shadow_full, geometry_full) = triangles("0");
    let (shadow, geometry) = triangles(&LOD_PX.to_string());
    // The far characters of a 16-head crowd at 320 x 180 are a few dozen
    // pixels tall: their coarse levels (a sixteenth to a thirty-second of
    // the triangles).
    assert!(
        geometry * 4 < geometry_full,
        "{geometry} of {geometry_full}"
    );
    assert!(shadow * 4 < shadow_full, "{shadow} of {shadow_full}");
    // The frame against the full meshes': the same skin pixels but a few
    // along the silhouettes (lavapipe: 24 333 against 24 347), and the
    // diffuse light over skin within a relative RMSE of 0.15 (lavapipe
    // measured 0.127 at 1 px with levels down to 1/64 of the triangles,
    // 0.096 when they stopped at 1/16: the shading of a coarse level's
    // larger triangles, interpolating the full mesh's normals, and not its
    // outline, is most of it, which is why the levels are off by default).
    let ctx = common::ctx();
    let full = Renderer::new(&ctx, &dermis::scene::default_scene(), &settings(0.0))
        .unwrap()
        .capture(false)
        .unwrap();
    let lod = Renderer::new(&ctx, &dermis::scene::default_scene(), &settings(LOD_PX))
        .unwrap()
        .capture(false)
        .unwrap();
    let skin = |c: &dermis::render::Capture| c.diffuse.iter().filter(|p| p[3] > 0.0).count();
    let (a, b) = (skin(&full), skin(&lod));
    assert!(a.abs_diff(b) * 50 < a, "skin pixels {b} against {a}");
    let (mut num, mut den) = (0.0f64, 0.0f64);
    for (p, q) in full.diffuse.iter().zip(&lod.diffuse) {
        if p[3] > 0.0 && q[3] > 0.0 {
            for c in 0..3 {
                num += f64::from(p[c] - q[c]).powi(2);
                den += f64::from(p[c]).powi(2);
            }
        }
    }
    let rmse = (num / den).sqrt();
    eprintln!(
        "levels of detail at 1 px: relative RMSE {rmse:.4} over skin, {b} skin pixels of {a}"
    );
    assert!(rmse < 0.15, "relative RMSE {rmse}");
    assert!(rmse > 0.0, "the levels changed nothing");
}
