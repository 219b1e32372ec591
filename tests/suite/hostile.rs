//! Hostile but fair input on the GPU (issue 11), lavapipe with validation on:
//! a texture larger than the device allows, a far outlier vertex, a flat object,
//! and the extremes of every documented range, each rendered for real. (The CLI
//! sweep of every flag is in tests/suite/cli.rs; the glTF fuzzer in tests/suite/gltf_fuzz.rs.)

use crate::common;

use dermis::render::{Capture, RenderSettings};
use dermis::run::{run, RunOptions};
use dermis::scene::mesh::Texture;
use dermis::scene::procedural::flat_card;
use dermis::scene::{default_scene, egg_scene, scene_from_head, Scene};
use dermis::vk::context::Context;
use glam::{Mat4, Vec3};

fn small() -> RenderSettings {
    RenderSettings {
        width: 64,
        height: 36,
        shadow_size: 256,
        ..RenderSettings::study()
    }
}

fn capture(ctx: &Context, scene: &Scene, s: &RenderSettings) -> Capture {
    let out = run(ctx, scene, s, &RunOptions::capture_once("hostile"))
        .unwrap_or_else(|e| panic!("{}: {e:#}", scene.name));
    ctx.check_validation("after the render").unwrap();
    out.capture.expect("a capture")
}

/// Pixels of skin in the frame (the diffuse alpha is the SSS strength).
fn skin_pixels(c: &Capture) -> usize {
    c.diffuse.iter().filter(|p| p[3] > 0.0).count()
}

fn assert_finite(c: &Capture, what: &str) {
    assert_eq!(c.hdr_nonfinite, 0, "{what}: non-finite HDR pixels");
    assert!(
        c.diffuse.iter().flatten().all(|v| v.is_finite()),
        "{what}: non-finite diffuse light"
    );
}

// Issue 11: a texture larger than maxImageDimension2D was created anyway (a
// validation error; undefined behaviour without validation). It is downscaled
// to the limit, with a warning.
#[test]
fn a_texture_larger_than_the_device_allows_is_downscaled() {
    let ctx = common::ctx();
    let max = ctx.facts.max_image_dimension_2d;
    let mut scene = default_scene();
    let (w, h) = (max + 1, 2);
    scene.head.material.base_color = Some(Texture {
        width: w,
        height: h,
        rgba8: vec![200; (w * h * 4) as usize],
    });
    let c = capture(&ctx, &scene, &small());
    assert!(skin_pixels(&c) > 100);
    assert_finite(&c, "oversized texture");
    ctx.finish().unwrap();
}

// Issue 11: a flat object was framed edge-on, so only its shadow showed. It now
// faces the camera with its largest extent, however it lies.
#[test]
fn a_flat_object_is_seen_face_on() {
    use std::f32::consts::{FRAC_PI_2, PI};
    let ctx = common::ctx();
    let s = RenderSettings {
        distance_heads: 2.0,
        ..small()
    };
    for (m, name) in [
        (Mat4::IDENTITY, "facing +Z"),
        (Mat4::from_rotation_y(FRAC_PI_2), "facing +X"),
        (Mat4::from_rotation_y(PI), "facing -Z"),
        (Mat4::from_rotation_x(-FRAC_PI_2), "lying flat"),
    ] {
        let scene = scene_from_head(name, flat_card(2.0, 1.0, m, [0.6, 0.45, 0.4]), None).unwrap();
        let c = capture(&ctx, &scene, &s);
        // Two heads' distance from a card two units wide: a third of the frame
        // or more is card (edge-on: none).
        let frac = skin_pixels(&c) as f64 / (64.0 * 36.0);
        assert!(
            frac > 0.3,
            "{name}: {:.0}% of the frame is card",
            frac * 100.0
        );
        assert_finite(&c, name);
    }
    ctx.finish().unwrap();
}

// Issue 11: one vertex at 1e31 (one flipped byte) turned the whole frame black:
// the camera and the shadow map framed the universe. The head now shows as
// without the vertex (the triangles that use it cross the screen as thin slivers).
#[test]
fn a_far_outlier_vertex_leaves_the_head_in_the_frame() {
    let ctx = common::ctx();
    let clean = egg_scene();
    let good = scene_from_head("clean", clean.head.clone(), None).unwrap();
    let reference = skin_pixels(&capture(&ctx, &good, &small()));
    assert!(reference > 200, "{reference}");
    for far in [
        Vec3::new(0.0, 1e31, 0.0),
        Vec3::new(1e31, -1e31, 0.0),
        Vec3::new(0.0, 0.0, -1e31),
    ] {
        let mut head = clean.head.clone();
        head.mesh.vertices[1000].position = far.into();
        let bad = scene_from_head("outlier", head, None).unwrap();
        let c = capture(&ctx, &bad, &small());
        let n = skin_pixels(&c);
        assert!(
            (n as f64 - reference as f64).abs() < 0.1 * reference as f64,
            "{far}: {n} skin pixels, {reference} without the vertex"
        );
        assert_finite(&c, "outlier");
    }
    ctx.finish().unwrap();
}

// Every end of every documented range renders finite images (issue 11: huge
// values gave NaN pixels or black frames; they are refused now, and what is
// accepted must be safe). Values the CLI sweep accepts are here too.
#[test]
fn the_ends_of_every_range_render_finite_images() {
    let ctx = common::ctx();
    let scene = default_scene();
    let sep = common::m("separable");
    let base = small();
    type Edit = fn(&mut RenderSettings);
    let cases: Vec<(&str, Edit)> = vec![
        ("exposure max", |s| s.exposure = 1024.0),
        ("exposure min", |s| s.exposure = 1.0 / 1024.0),
        ("light max", |s| {
            s.light.intensity = dermis::scene::light::MAX_INTENSITY
        }),
        ("light 0", |s| s.light.intensity = 0.0),
        ("ambient max", |s| {
            s.ambient = dermis::render::settings::MAX_AMBIENT
        }),
        ("ambient 0", |s| s.ambient = 0.0),
        ("distance max", |s| {
            s.distance_heads = dermis::render::settings::MAX_DISTANCE_HEADS
        }),
        ("distance 1e-30", |s| s.distance_heads = 1e-30),
        ("light from below", |s| s.light.elevation_deg = -90.0),
        ("light behind", |s| s.light.azimuth_deg = -180.0),
        ("fovy min", |s| s.fovy_deg = 0.51),
        ("fovy max", |s| s.fovy_deg = 169.9),
        ("tile 1", |s| s.sss_region_tile = 1),
        ("falloff max", |s| {
            *s = s.clone().with(
                common::m("separable"),
                &[("falloff", "100,100,100"), ("strength", "1,1,1")],
            )
        }),
        ("falloff 1e-30", |s| {
            *s = s
                .clone()
                .with(common::m("separable"), &[("falloff", "1e-30,1e-30,1e-30")])
        }),
        ("width max", |s| {
            *s = s
                .clone()
                .with(common::m("separable"), &[("sss-width-mm", "1000")])
        }),
        ("width 1e-30", |s| {
            *s = s
                .clone()
                .with(common::m("separable"), &[("sss-width-mm", "1e-30")])
        }),
        ("strength 0", |s| {
            *s = s
                .clone()
                .with(common::m("separable"), &[("strength", "0,0,0")])
        }),
    ];
    for (what, edit) in cases {
        let mut s = base.clone().with(sep, &[]);
        edit(&mut s);
        s.validate().unwrap_or_else(|e| panic!("{what}: {e:#}"));
        let c = capture(&ctx, &scene, &s);
        assert_finite(&c, what);
    }
    // The ground truth at the smallest density (one sample a triangle).
    let s = base
        .clone()
        .with(common::m("reference"), &[("density", "1e-30")]);
    assert_finite(&capture(&ctx, &egg_scene(), &s), "density 1e-30");
    ctx.finish().unwrap();
}

// ---- Every file in through one door (issue 15, item 11) --------------------------
// Each reader of a user-supplied file is tried with what a hostile user hands it: a
// FIFO (opening it would block until a writer came), /dev/zero (it never ends), a
// decompression bomb (a PNG of a few dozen bytes declaring 100000 x 100000 pixels)
// and files beside a model. Each ends in one clean error line, or in the render it
// would have been without them.

use dermis::scene::gltf_load::fixture::{temp_dir, Container, Model};
use dermis::scene::gltf_load::{load_head_with_notes, TextureOverrides};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Runs `f` on a thread and fails (instead of hanging) when it takes a minute.
fn within_a_minute<T: Send + 'static>(what: &str, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(Duration::from_secs(60))
        .unwrap_or_else(|_| panic!("{what}: still reading after a minute (a FIFO was opened?)"))
}

fn mkfifo(p: &Path) {
    let ok = std::process::Command::new("mkfifo")
        .arg(p)
        .status()
        .expect("run mkfifo");
    assert!(ok.success(), "mkfifo {}", p.display());
}

/// A PNG whose header declares `w` x `h` RGBA8 pixels but whose one IDAT chunk
/// holds a few bytes: only a decoder that allocates first would notice anything.
fn png_bomb(w: u32, h: u32) -> Vec<u8> {
    fn crc32(b: &[u8]) -> u32 {
        let mut c = !0u32;
        for &x in b {
            c ^= x as u32;
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xEDB8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }
    let chunk = |v: &mut Vec<u8>, kind: &[u8], data: &[u8]| {
        let mut c = kind.to_vec();
        c.extend(data);
        v.extend((data.len() as u32).to_be_bytes());
        v.extend(&c);
        v.extend(crc32(&c).to_be_bytes());
    };
    let mut ihdr = w.to_be_bytes().to_vec();
    ihdr.extend(h.to_be_bytes());
    ihdr.extend([8, 6, 0, 0, 0]);
    let mut v = b"\x89PNG\r\n\x1a\n".to_vec();
    chunk(&mut v, b"IHDR", &ihdr);
    chunk(
        &mut v,
        b"IDAT",
        &[0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01],
    );
    chunk(&mut v, b"IEND", &[]);
    v
}

/// One line, no panic, containing every phrase.
fn clean_error<T>(r: anyhow::Result<T>, what: &str, phrases: &[&str]) {
    let e = match r {
        Ok(_) => panic!("{what}: accepted"),
        Err(e) => format!("{e:#}"),
    };
    assert!(!e.contains('\n'), "{what}: not one line: {e}");
    for p in phrases {
        assert!(e.contains(p), "{what}: '{p}' not in: {e}");
    }
}

/// A FIFO, /dev/zero and a bomb in a fresh folder: (fifo, dev_zero_link, bomb).
fn hostile_files(dir: &Path, stem: &str, ext: &str) -> (PathBuf, PathBuf, PathBuf) {
    let fifo = dir.join(format!("{stem}_fifo.{ext}"));
    mkfifo(&fifo);
    let zero = dir.join(format!("{stem}_zero.{ext}"));
    std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
    let bomb = dir.join(format!("{stem}_bomb.{ext}"));
    std::fs::write(&bomb, png_bomb(100_000, 100_000)).unwrap();
    (fifo, zero, bomb)
}

#[test]
fn the_scene_door_refuses_fifos_dev_zero_and_bombs() {
    let dir = temp_dir("hostile-scene");
    let (fifo, zero, _) = hostile_files(&dir, "scene", "glb");
    for p in [fifo, zero] {
        let what = p.display().to_string();
        let r = within_a_minute(&what, move || {
            dermis::scene::load_gltf_scene(&p, &TextureOverrides::default(), None).map(|_| ())
        });
        clean_error(r, &what, &["scene file is not a regular file"]);
    }
    // A buffer and an image URI naming a FIFO or /dev/zero, and an embedded bomb.
    let fifo = dir.join("buffer.fifo");
    mkfifo(&fifo);
    for uri in ["buffer.fifo", "/dev/zero"] {
        let mut m = Model::grid(3, png_bomb(1, 1));
        m.json["buffers"][0]["uri"] = serde_json::json!(uri);
        let p = m.write(Container::DataUri, &dir, "buf");
        let r = within_a_minute(uri, move || {
            load_head_with_notes(&p, &TextureOverrides::default()).map(|_| ())
        });
        clean_error(r, uri, &["buffer 0 is not a regular file"]);
    }
    let m = Model::grid(3, png_bomb(100_000, 100_000));
    let p = m.write(Container::Glb, &dir, "bomb");
    clean_error(
        load_head_with_notes(&p, &TextureOverrides::default()).map(|_| ()),
        "embedded bomb",
        &[
            "albedo image 0",
            "100000x100000 pixels",
            "more than the 512 MiB allowed",
        ],
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn the_texture_door_refuses_fifos_dev_zero_and_bombs() {
    let dir = temp_dir("hostile-texture");
    let scene = Model::triangle(true, true, [0.0; 3]).write(Container::DataUri, &dir, "tri");
    let (fifo, zero, bomb) = hostile_files(&dir, "given", "png");
    for (p, phrase) in [
        (fifo, "albedo texture is not a regular file"),
        (zero, "albedo texture is not a regular file"),
        (bomb, "100000x100000 pixels"),
    ] {
        let what = p.display().to_string();
        let scene = scene.clone();
        let r = within_a_minute(&what, move || {
            let o = TextureOverrides {
                albedo: Some(p),
                ..Default::default()
            };
            load_head_with_notes(&scene, &o).map(|_| ())
        });
        clean_error(r, &what, &[phrase]);
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn the_budget_doors_refuse_fifos_dev_zero_and_out_of_range_files() {
    use dermis::budget::frames::load_frame;
    use dermis::budget::profile::Profile;
    use dermis::report;
    let dir = temp_dir("hostile-budget");
    let (fifo, zero, _) = hostile_files(&dir, "profile", "toml");
    for p in [fifo.clone(), zero.clone()] {
        let what = p.display().to_string();
        let r = within_a_minute(&what, move || {
            Profile::load(p.to_str().unwrap()).map(|_| ())
        });
        clean_error(r, &what, &["profile is not a regular file"]);
    }
    let (fifo, zero, _) = hostile_files(&dir, "frame", "json");
    for p in [fifo, zero] {
        let what = p.display().to_string();
        let q = p.clone();
        let r = within_a_minute(&what, move || load_frame(&q).map(|_| ()));
        clean_error(r, &what, &["stored frame is not a regular file"]);
        let r = within_a_minute(&what, move || report::load(&p).map(|_| ()));
        clean_error(r, &what, &["report is not a regular file"]);
    }
    // A profile and a stored frame whose resolution render would refuse.
    let xbox = dermis::budget::profile::profiles_dir().join("xbox360.toml");
    let text = std::fs::read_to_string(xbox).unwrap();
    let p = dir.join("wide.toml");
    std::fs::write(&p, text.replace("width_px = 1280", "width_px = 100000")).unwrap();
    clean_error(
        Profile::load(p.to_str().unwrap()),
        "wide profile",
        &["target.width_px", "1..=16384", "100000"],
    );
    let frame = |width: u32, height: u32, area: u32, fragments: u64| {
        use dermis::budget::input::{FrameInput, PassInput};
        use dermis::graph::work::{PassRole, Work};
        let mut pass = PassInput::new(
            "geometry",
            PassRole::Geometry,
            Work::Raster {
                shader: None,
                color: Vec::new(),
                depth_stencil: None,
                width: area,
                height: area,
                triangles: 2,
                msaa: 1,
                clears: Vec::new(),
            },
        );
        pass.fragments = fragments;
        let f = FrameInput {
            label: "hostile".into(),
            width,
            height,
            passes: vec![pass],
            provenance: Vec::new(),
        };
        let p = dir.join("frame.json");
        std::fs::write(&p, serde_json::to_vec(&f).unwrap()).unwrap();
        load_frame(&p)
    };
    frame(64, 64, 64, 2 * 64 * 64).unwrap();
    clean_error(
        frame(64, 0, 64, 0),
        "zero-height frame",
        &["height must be within 1..=16384"],
    );
    clean_error(
        frame(64, 64, 100_000, 0),
        "huge render area",
        &["render area width must be within 1..=16384"],
    );
    clean_error(
        frame(64, 64, 64, 2 * 64 * 64 + 1),
        "more fragments than the triangles cover",
        &["fragments is 8193, more than its 2 triangles can cover in 64x64"],
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn the_compare_door_refuses_fifos_dev_zero_and_bombs() {
    let dir = temp_dir("hostile-compare");
    // Output folders as `render` writes them, each with one hostile file in place.
    type Make = fn(&Path);
    let cases: [(&str, Make); 3] = [
        ("fifo", |p| mkfifo(p)),
        ("zero", |p| {
            std::os::unix::fs::symlink("/dev/zero", p).unwrap()
        }),
        ("bomb", |p| {
            std::fs::write(p, png_bomb(100_000, 100_000)).unwrap()
        }),
    ];
    for (name, make) in cases {
        let a = dir.join(name);
        std::fs::create_dir_all(&a).unwrap();
        make(&a.join("diffuse.exr"));
        let what = format!("compare with a {name} as diffuse.exr");
        let b = a.clone();
        let out = dir.join("out");
        let r = within_a_minute(&what, move || {
            dermis::eval::compare::compare(&a, &b, None, &out, "test").map(|_| ())
        });
        let phrase = if name == "bomb" {
            "100000x100000 pixels"
        } else {
            "EXR image is not a regular file"
        };
        clean_error(r, &what, &[phrase]);
    }
    let _ = std::fs::remove_dir_all(dir);
}

// A file beside a model is taken as a texture only by the naming rule
// (`gltf_load::textures`), and a file beside it that the rule does not match, or one
// it matches that cannot be read, never stops or changes its render.
#[test]
fn files_beside_a_model_never_stop_or_change_its_render() {
    let ctx = common::ctx();
    let dir = temp_dir("hostile-beside");
    let scene_file = Model::grid(6, {
        let img = image::RgbaImage::from_fn(4, 4, |x, y| {
            image::Rgba([(x * 60) as u8, (y * 60) as u8, 150, 255])
        });
        let mut out = std::io::Cursor::new(Vec::new());
        img.write_to(&mut out, image::ImageFormat::Png).unwrap();
        out.into_inner()
    })
    .write(Container::Glb, &dir, "grid");
    // Loaded on a thread (a FIFO opened by mistake fails the test instead of
    // hanging it), rendered here.
    let load = |scene_file: PathBuf| {
        within_a_minute("load beside hostile files", move || {
            let l = load_head_with_notes(&scene_file, &TextureOverrides::default()).unwrap();
            (l.object, l.warnings, l.notes)
        })
    };
    let render = |head| {
        capture(
            &ctx,
            &scene_from_head("grid", head, None).unwrap(),
            &small(),
        )
    };
    let (head, w, n) = load(scene_file.clone());
    assert!(w.is_empty() && n.is_empty(), "{w:?} {n:?}");
    let clean = render(head);
    // Unrelated: names no role (never opened, even a FIFO or a bomb).
    let (fifo, zero, bomb) = hostile_files(&dir, "photo", "png");
    std::fs::write(dir.join("notes.txt"), "hello").unwrap();
    std::fs::write(dir.join("collar.jpg"), b"not a jpeg").unwrap();
    let (head, w, n) = load(scene_file.clone());
    assert!(w.is_empty() && n.is_empty(), "{w:?} {n:?}");
    assert_eq!(
        render(head).ldr,
        clean.ldr,
        "an unrelated file changed the render"
    );
    // Named by the rule but unreadable: left out with a warning. The model's own
    // albedo keeps that role; the others find nothing usable.
    std::fs::rename(&fifo, dir.join("skin_normal.png")).unwrap();
    std::fs::rename(&zero, dir.join("skin_spec.png")).unwrap();
    std::fs::rename(&bomb, dir.join("skin_col.png")).unwrap();
    let (head, w, n) = load(scene_file.clone());
    assert_eq!(
        render(head).ldr,
        clean.ldr,
        "a file beside the model changed its render"
    );
    assert!(
        w.iter()
            .any(|w| w.contains("skin_normal.png beside the scene not used")),
        "{w:?}"
    );
    assert!(
        w.iter()
            .any(|w| w.contains("skin_spec.png beside the scene not used")),
        "{w:?}"
    );
    assert!(
        n.iter()
            .any(|n| n
                .contains("skin_col.png beside the scene not used: the glTF material has its own")),
        "{n:?}"
    );
    let _ = std::fs::remove_dir_all(dir);
    ctx.finish().unwrap();
}

// The same doors from the command line: each hostile file ends in exit 1 and one
// `error:` line naming it, within a minute (a child still running then is killed
// and fails the test).
#[test]
fn the_command_line_ends_hostile_files_in_one_error_line() {
    let dir = temp_dir("hostile-cli");
    let (fifo, zero, bomb) = hostile_files(&dir, "input", "png");
    let out = dir.join("out");
    let o = out.to_str().unwrap();
    let (f, z, b) = (
        fifo.to_str().unwrap(),
        zero.to_str().unwrap(),
        bomb.to_str().unwrap(),
    );
    let fifo_dir = dir.join("fifo_run");
    std::fs::create_dir_all(&fifo_dir).unwrap();
    mkfifo(&fifo_dir.join("diffuse.exr"));
    let fd = fifo_dir.to_str().unwrap();
    let render = |extra: &[&str]| -> Vec<String> {
        let mut a: Vec<String> = [
            "render", "--device", "llvmpipe", "--width", "64", "--height", "36", "--frames", "1",
            "--warmup", "0", "--out", o,
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        a.extend(extra.iter().map(|s| s.to_string()));
        a
    };
    let cases: Vec<(Vec<String>, &str)> = vec![
        (render(&["--scene", f]), "scene file is not a regular file"),
        (render(&["--scene", z]), "scene file is not a regular file"),
        (
            ["compare", fd, fd].iter().map(|s| s.to_string()).collect(),
            "EXR image is not a regular file",
        ),
        (
            ["budget", "--device", "llvmpipe", "--profile", z, "--out", o]
                .iter()
                .map(|s| s.to_string())
                .collect(),
            "profile is not a regular file",
        ),
    ];
    let scene = Model::triangle(true, true, [0.0; 3]).write(Container::DataUri, &dir, "tri");
    let s = scene.to_str().unwrap();
    let mut cases = cases;
    cases.push((
        render(&["--scene", s, "--albedo", f]),
        "albedo texture is not a regular file",
    ));
    cases.push((
        render(&["--scene", s, "--spec-map", b]),
        "100000x100000 pixels",
    ));
    for (args, phrase) in cases {
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_dermis"))
            .args(&args)
            .env("RUST_BACKTRACE", "0")
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("run dermis");
        let start = std::time::Instant::now();
        let status = loop {
            if let Some(s) = child.try_wait().unwrap() {
                break s;
            }
            if start.elapsed() > Duration::from_secs(60) {
                let _ = child.kill();
                panic!("{args:?}: still running after a minute");
            }
            std::thread::sleep(Duration::from_millis(50));
        };
        let mut err = String::new();
        std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
        let lines: Vec<&str> = err
            .lines()
            .filter(|l| !l.trim().is_empty() && !l.starts_with("note: "))
            .collect();
        assert_eq!(status.code(), Some(1), "{args:?}: {err}");
        assert_eq!(lines.len(), 1, "{args:?}: not one line: {err}");
        assert!(
            lines[0].starts_with("error: ") && lines[0].contains(phrase),
            "{args:?}: '{phrase}' not in: {err}"
        );
    }
    let _ = std::fs::remove_dir_all(dir);
}
