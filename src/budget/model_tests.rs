// The tests of model.rs (a file of their own to keep both short): every term
// of the combining rule priced on real profiles.
use super::*;
use crate::budget::input::PassInput;
use crate::budget::profile::Quantity;
use crate::work::{ColorWrite, Fetch, Filter, Format, ImageUse, ImageUseKind, ShaderWork, Work};

fn prof(name: &str) -> Profile {
    Profile::load(name).unwrap()
}

fn blur(frags: u64, taps: f64) -> PassInput {
    let mut p = PassInput::new(
        "blur",
        PassRole::Sss,
        Work::Raster {
            shader: Some(ShaderWork {
                fetches: vec![Fetch {
                    texture: "colorTex".into(),
                    format: Format::Rgba16Float,
                    filter: Filter::Bilinear,
                    count: taps,
                    exact: true,
                    coherent: true,
                    spread: Vec::new(),
                }],
                alu: 4.0 * taps,
                ..Default::default()
            }),
            color: vec![ColorWrite {
                format: Format::Rgba16Float,
                blend: false,
            }],
            depth_stencil: None,
            width: 1280,
            height: 720,
            triangles: 1,
            msaa: 1,
            clears: vec![],
        },
    );
    p.fragments = frags;
    p.samples_passed = frags;
    p
}

fn frame(passes: Vec<PassInput>) -> FrameInput {
    FrameInput {
        label: "test".into(),
        width: 1280,
        height: 720,
        passes,
        provenance: vec![],
    }
}

#[test]
fn doubled_work_costs_twice_on_a_unit_bound_profile() {
    for name in ["xbox360", "geforce-gtx-580", "nvidia-h100"] {
        let p = prof(name);
        let one = price_units(&p, &frame(vec![blur(500_000, 17.0)]));
        let two = price_units(&p, &frame(vec![blur(1_000_000, 17.0)]));
        // Without the fixed cost and setup, every unit is linear in the work.
        let params = ModelParams::PEAK;
        let a = one[0].units.combine(&params) - one[0].units.geometry;
        let b = two[0].units.combine(&params) - two[0].units.geometry;
        assert!((b / a - 2.0).abs() < 1e-9, "{name}: {a} -> {b}");
        // Twice the taps on the same pixels: texture-bound, so twice the time.
        let t = price_units(&p, &frame(vec![blur(500_000, 34.0)]));
        assert!(
            t[0].units.texture > t[0].units.fill,
            "{name} should be texture-bound"
        );
        assert!((t[0].units.texture / one[0].units.texture - 2.0).abs() < 1e-9);
    }
}

/// `blur` with its taps incoherent, landing `spread` away.
fn rotated(spread: Vec<crate::work::Spread>) -> PassInput {
    let mut p = blur(1_000_000, 16.0);
    if let Work::Raster {
        shader: Some(s), ..
    } = &mut p.work
    {
        s.fetches[0].coherent = false;
        s.fetches[0].spread = spread;
    }
    p
}

#[test]
fn incoherent_taps_cost_more_the_farther_they_land() {
    use crate::work::Spread;
    let p = prof("nvidia-h200");
    let params = ParamSet::fitted().probed;
    let at = |spread: Vec<Spread>| {
        let u = price_units(&p, &frame(vec![rotated(spread)]));
        u[0].units.scaled(&params).texture_incoherent
    };
    let coherent = price_units(&p, &frame(vec![blur(1_000_000, 16.0)]))[0]
        .units
        .scaled(&params)
        .texture;
    let one = |r: f64| {
        at(vec![Spread {
            share: 1.0,
            radius_px: r,
        }])
    };
    let undeclared = at(Vec::new());
    // Within a texel of their pixel: nearly the coherent cost; far out:
    // the full factor, as taps of no declared spread are priced.
    assert!(
        (one(0.125) / coherent - 1.0).abs() < 0.02,
        "{}",
        one(0.125) / coherent
    );
    assert!((one(128.0) / undeclared - 1.0).abs() < 0.01);
    let radii = [0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0];
    for w in radii.windows(2) {
        assert!(one(w[0]) < one(w[1]), "{w:?}");
    }
    // At the half radius: half the extra cost (between the bins around
    // it, linear in log radius: within the shape's curvature).
    let h = params.incoherent_radius_px;
    let mid = coherent * params.incoherence(h);
    assert!((one(h) / mid - 1.0).abs() < 0.05, "{} vs {mid}", one(h));
    // Shares weigh: half the taps near, half far, is the mean of the two.
    let both = at(vec![
        Spread {
            share: 0.5,
            radius_px: 0.5,
        },
        Spread {
            share: 0.5,
            radius_px: 16.0,
        },
    ]);
    assert!((both - (one(0.5) + one(16.0)) / 2.0).abs() < 1e-9 * both);
}

#[test]
fn texture_time_at_known_rates() {
    // 1M fragments x 16 bilinear RGBA16F taps on the Xbox 360: 64-bit
    // texels at half of 8 Gtexel/s: 16e6 x 2 / 8e9 = 4 ms.
    let p = prof("xbox360");
    let u = price_units(&p, &frame(vec![blur(1_000_000, 16.0)]));
    assert!(
        (u[0].units.texture - 4.0).abs() < 1e-9,
        "{}",
        u[0].units.texture
    );
    // Its RGBA16F write at 2 Gpix/s: 0.5 ms.
    assert!((u[0].units.fill - 0.5).abs() < 1e-9, "{}", u[0].units.fill);
}

#[test]
fn a_sampled_target_forces_one_resolve_of_its_bytes() {
    let p = prof("xbox360");
    let mut a = blur(921_600, 1.0);
    a.name = "geometry".into();
    a.images.push(ImageUse {
        image: "diffuse".into(),
        format: Format::Rgba16Float,
        width: 1280,
        height: 720,
        kind: ImageUseKind::ColorTarget,
    });
    let mut b = blur(921_600, 17.0);
    b.images.push(ImageUse {
        image: "diffuse".into(),
        format: Format::Rgba16Float,
        width: 1280,
        height: 720,
        kind: ImageUseKind::Sampled,
    });
    let mut c = b.clone();
    c.name = "second read".into();
    let u = price_units(&p, &frame(vec![a, b, c]));
    let e = u[0].edram.as_ref().unwrap();
    assert_eq!(e.resolves.len(), 1, "one resolve however many reads");
    assert_eq!(e.resolves[0].bytes, 7_372_800);
    assert_eq!(e.resolves[0].forced_by, "blur");
    // At the profile's 16 GB/s: 0.46 ms; never under the 22.4 GB/s bound.
    let ms = e.resolves[0].ms.unwrap();
    assert!(
        ms >= 7_372_800.0 / 22.4e9 * 1e3 && (ms - 0.4608).abs() < 1e-9,
        "{ms}"
    );
    assert!(u[1].edram.as_ref().unwrap().resolves.is_empty());
    // Not on a GPU without eDRAM.
    let d = price_units(
        &prof("geforce-gtx-580"),
        &frame(vec![u_clone_a(), blur(1, 1.0)]),
    );
    assert!(d[0].edram.is_none() && d[0].units.resolve == 0.0);
}

fn u_clone_a() -> PassInput {
    blur(921_600, 1.0)
}

#[test]
fn mrt_pass_that_overflows_edram_is_tiled() {
    // The geometry pass's three 32 bpp MRTs + depth at 720p: 2 screen tiles.
    let p = prof("xbox360");
    let mut g = blur(921_600, 1.0);
    if let Work::Raster {
        color,
        depth_stencil,
        triangles,
        ..
    } = &mut g.work
    {
        *color = vec![
            ColorWrite {
                format: Format::Rgba8Unorm,
                blend: false,
            },
            ColorWrite {
                format: Format::Rgba8Unorm,
                blend: false,
            },
            ColorWrite {
                format: Format::R32Float,
                blend: false,
            },
        ];
        *depth_stencil = Some(crate::work::DepthStencilUse {
            format: Format::D24UnormS8Uint,
            depth_test: true,
            depth_write: true,
            stencil_test: false,
            stencil_write: true,
        });
        *triangles = 100_000;
    }
    let u = price_units(&p, &frame(vec![g.clone()]));
    let e = u[0].edram.as_ref().unwrap();
    assert_eq!(
        (e.screen_tiles, e.predicated_tiling, e.footprint_tiles),
        (2, true, 2880)
    );
    // Geometry re-submitted: 1.25x the setup time of 100k triangles at 0.5 G/s.
    assert!((u[0].units.geometry - 100_000.0 * 1.25 / 0.5e9 * 1e3).abs() < 1e-12);
}

#[test]
fn unrenderable_format_is_substituted_and_priced() {
    // RGBA32F cannot be rendered on the Xbox 360: nearest is RGBA16F-class.
    let p = prof("xbox360");
    let mut b = blur(1000, 1.0);
    if let Work::Raster { color, .. } = &mut b.work {
        color[0].format = Format::Rgba32Float;
    }
    let u = price_units(&p, &frame(vec![b]));
    let s = &u[0].substitutions[0];
    assert_eq!(s.wanted, "rgba32-float");
    assert_eq!(s.used.as_deref(), Some("rgba16-float"));
    assert!(s.fill_ms.unwrap() > 0.0);
    assert!(u[0].unpriced.is_empty());
}

/// A 1920 x 1080 pass writing one RGBA8 target at `msaa` samples: every
/// pixel covered, `partial` of them by two fragments.
fn multisampled(msaa: u32, partial: u64) -> PassInput {
    let px = 1920 * 1080;
    let mut p = blur(px + partial, 0.0);
    if let Work::Raster {
        shader,
        color,
        msaa: m,
        width,
        height,
        ..
    } = &mut p.work
    {
        *shader = None;
        color[0].format = Format::Rgba8Unorm;
        *m = msaa;
        (*width, *height) = (1920, 1080);
    }
    p.samples_passed = px * u64::from(msaa);
    p
}

#[test]
fn compressed_msaa_pays_its_samples_only_where_edges_cross_pixels() {
    let px = 1920.0 * 1080.0;
    let units = |prof: &str, msaa, partial| {
        price_units(&self::prof(prof), &frame(vec![multisampled(msaa, partial)]))[0].units
    };
    // GTX 470 (GF100: compressed pixels at the pixel rate, 24.3 G/s;
    // uncompressed samples at 24.3 G samples/s; 133.9 GB/s).
    let one = units("geforce-gtx-470", 1, 0);
    let flat = units("geforce-gtx-470", 8, 0);
    assert!((one.fill - px / 24.3e9 * 1e3).abs() < 1e-12);
    assert!(
        (flat.fill - one.fill).abs() < 1e-12,
        "no edge: 8x at 1x's cost"
    );
    assert!((flat.memory - one.memory).abs() < 1e-12);
    let e = 200_000.0;
    let edged = units("geforce-gtx-470", 8, 200_000);
    let want_fill = ((px - e) / 24.3e9 + e * 8.0 / 24.3e9) * 1e3;
    assert!(
        (edged.fill - want_fill).abs() < 1e-12,
        "{} {want_fill}",
        edged.fill
    );
    let stored = px * (1.0 + e / px * 7.0);
    assert!((edged.memory - stored * 4.0 / 133.9e9 * 1e3).abs() < 1e-12);
    // 9800 GTX+ (G92: 47.2 G samples/s through the ROPs whatever the
    // compression): 4x costs 1x's pixel slots, 8x twice them.
    let g1 = units("geforce-9800-gtx-plus", 1, 0);
    let g4 = units("geforce-9800-gtx-plus", 4, 0);
    let g8 = units("geforce-9800-gtx-plus", 8, 0);
    assert!((g4.fill - g1.fill).abs() < 1e-12);
    assert!((g8.fill / g1.fill - 2.0).abs() < 1e-9);
    // Without compression (the Steam Deck's profile) every sample is
    // stored: memory grows with the count.
    let d1 = units("steam-deck", 1, 0);
    let d4 = units("steam-deck", 4, 0);
    assert!((d4.memory / d1.memory - 4.0).abs() < 1e-9);
}

#[test]
fn depth_traffic_counts_each_sample_once() {
    // samples_passed already counts samples: at 4x a D32S8 target is
    // read and written once per sample, not per sample squared.
    let p = prof("steam-deck");
    let mut g = multisampled(4, 0);
    if let Work::Raster { depth_stencil, .. } = &mut g.work {
        *depth_stencil = Some(crate::work::DepthStencilUse {
            format: Format::D32FloatS8Uint,
            depth_test: true,
            depth_write: true,
            stencil_test: false,
            stencil_write: false,
        });
    }
    let with = price_units(&p, &frame(vec![g]))[0].units.memory;
    let without = price_units(&p, &frame(vec![multisampled(4, 0)]))[0]
        .units
        .memory;
    let samples = 1920.0 * 1080.0 * 4.0;
    let want = samples * 5.0 * 2.0 / 88.0e9 * 1e3;
    assert!(
        (with - without - want).abs() < 1e-12,
        "{} vs {want}",
        with - without
    );
}

#[test]
fn fast_depth_clears_cost_nothing() {
    let cleared = |prof: &str, f: Format| {
        let mut c = blur(0, 0.0);
        if let Work::Raster { clears, .. } = &mut c.work {
            *clears = vec![f];
        }
        price_units(&self::prof(prof), &frame(vec![c]))[0].units
    };
    // NVIDIA's fast Z clear (the GeForce profiles): no fill, no bytes.
    let z = cleared("geforce-9800-gtx-plus", Format::D32FloatS8Uint);
    assert_eq!((z.clear, z.memory), (0.0, 0.0));
    // A colour clear still writes every pixel at the fill rate.
    let c = cleared("geforce-9800-gtx-plus", Format::Rgba8Unorm);
    assert!((c.clear - 1280.0 * 720.0 / 11.8e9 * 1e3).abs() < 1e-12);
    // A profile without it pays the depth clear at its Z rate.
    assert!(cleared("steam-deck", Format::D32FloatS8Uint).clear > 0.0);
}

#[test]
fn missing_numbers_leave_the_pass_unpriced_and_named() {
    // The H100 profile has no MSAA rate: a 4x pass cannot be priced there.
    let p = prof("nvidia-h100");
    let mut m = blur(1000, 1.0);
    m.name = "msaa blur".into();
    if let Work::Raster { msaa, .. } = &mut m.work {
        *msaa = 4;
    }
    let b = price_frame(
        &p,
        &frame(vec![m, blur(1000, 1.0)]),
        &ParamSet::both(ModelParams::PEAK),
        Rescale::AsRun,
    );
    assert_eq!(b.passes[0].modelled_ms, None);
    assert_eq!(
        b.passes[0].unpriced,
        vec!["raster.msaa_gsamples".to_string()]
    );
    assert_eq!(b.unpriced_passes.len(), 1);
    assert!(b.unpriced_passes[0].starts_with("msaa blur"));
    assert!(b.passes[1].modelled_ms.is_some());
}

/// A compute pass of a million invocations at 240 instructions each.
fn gather() -> PassInput {
    PassInput::new(
        "gather",
        PassRole::Sss,
        Work::Compute {
            shader: ShaderWork {
                alu: 240.0,
                ..Default::default()
            },
            invocations: 1_000_000,
        },
    )
}

#[test]
fn a_dispatch_without_a_compute_path_is_priced_as_a_pixel_shader() {
    let p = prof("xbox360");
    let c = gather();
    let b = price_frame(
        &p,
        &frame(vec![c]),
        &ParamSet::both(ModelParams::PEAK),
        Rescale::AsRun,
    );
    assert!(b.unpriced_passes.is_empty());
    assert_eq!(b.passes[0].substitutions[0].wanted, "compute");
    // 240 instructions x 1M at Xenos' 24 G vector instructions/s: 10 ms.
    assert!((b.passes[0].terms_ms.alu - 10.0).abs() < 1e-9);
}

/// `n` fragments of a shader of `k` arithmetic instructions, nothing else.
fn alu_only(n: u64, k: f64) -> PassInput {
    let mut p = blur(n, 0.0);
    if let Work::Raster {
        shader: Some(s), ..
    } = &mut p.work
    {
        s.fetches.clear();
        s.alu = k;
    }
    p
}

#[test]
fn vector_issue_prices_an_instruction_per_alu_clock() {
    let alu = |prof: &Profile, n, k| price_units(prof, &frame(vec![alu_only(n, k)]))[0].units.alu;
    let (n, k) = (921_600u64, 177.0);
    let ms = |rate_g: f64| n as f64 * k / (rate_g * 1e9) * 1e3;
    // Xenos: 48 ALUs x 0.5 GHz, one instruction a clock whatever its width.
    let xbox = prof("xbox360");
    assert!(
        (alu(&xbox, n, k) - ms(24.0)).abs() < 1e-12,
        "{}",
        alu(&xbox, n, k)
    );
    // RSX: 24 pipes x 2 vec4 units x 0.5 GHz.
    assert!((alu(&prof("ps3"), n, k) - ms(24.0)).abs() < 1e-12);
    // SIMT lanes are unchanged: gflops / 2 (9800 GTX+: 470 GFLOPS).
    let g92 = prof("geforce-9800-gtx-plus");
    assert!(g92.alu.vector_ginstr.is_none());
    assert!((alu(&g92, n, k) - ms(235.0)).abs() < 1e-12);
    // The pairing bound: at the parameter's max the time halves.
    let mut paired = xbox.clone();
    paired.alu.vector_ginstr = Some(Quantity::Known(48.0));
    assert!((alu(&paired, n, k) - ms(24.0) / 2.0).abs() < 1e-12);
    // The old lane rule would have charged a fifth of it.
    let mut lanes = xbox.clone();
    lanes.alu.vector_ginstr = None;
    assert!((alu(&lanes, n, k) - ms(120.0)).abs() < 1e-12);
}

#[test]
fn vector_issue_of_a_compute_path_scales_with_its_share_of_the_peak() {
    // A vector-issue GPU whose compute dispatches reach half the pixel
    // shaders' flops issues half the instructions.
    let mut p = prof("xbox360");
    p.alu.compute_gflops = Quantity::Known(120.0);
    let c = gather();
    let u = price_units(&p, &frame(vec![c]));
    assert!(u[0].substitutions.is_empty());
    assert!(
        (u[0].units.alu - 240e6 / 12e9 * 1e3).abs() < 1e-12,
        "{}",
        u[0].units.alu
    );
}

#[test]
fn an_unknown_issue_rate_leaves_alu_passes_unpriced() {
    let mut p = prof("xbox360");
    p.alu.vector_ginstr = Some(Quantity::Unknown);
    let u = price_units(&p, &frame(vec![alu_only(1000, 10.0)]));
    assert_eq!(u[0].unpriced, vec!["alu.vector_ginstr".to_string()]);
}

/// `gather()` with `shared` bytes of workgroup memory an invocation.
fn staged(shared: f64) -> PassInput {
    let mut c = gather();
    if let Work::Compute { shader, .. } = &mut c.work {
        shader.alu = 0.0;
        shader.shared_bytes = shared;
    }
    c
}

#[test]
fn a_dispatch_and_a_fill_take_the_dispatch_fixed_cost() {
    let p = prof("nvidia-h100");
    let params = ModelParams {
        fixed_kpix_per_pass: 10.0,
        fixed_kpix_per_dispatch: 100.0,
        ..ModelParams::PEAK
    };
    let fill = PassInput::new(
        "reset",
        PassRole::Sss,
        Work::Clear {
            texels: 4,
            bytes_per_texel: 4,
        },
    );
    let u = price_units(&p, &frame(vec![staged(0.0), fill, alu_only(1, 0.0)]));
    // 100 thousand pixels at the RGBA8 fill probe's 13.97 G/s: 0.0071582 ms
    // (the fill's own 4 texels add under 1e-6 ms).
    for k in [0, 1] {
        assert!(u[k].units.dispatch, "{}", u[k].name);
        let ms = u[k].modelled_ms(&params).unwrap_or(0.0);
        assert!(
            (ms - 1e5 / 13.97e9 * 1e3).abs() < 1e-6,
            "{}: {ms}",
            u[k].name
        );
    }
    // A draw keeps the per-pass cost (its one fragment's work adds 2e-6 ms).
    assert!(!u[2].units.dispatch);
    let ms = u[2].modelled_ms(&params).unwrap_or(0.0);
    assert!((ms - 1e4 / 13.97e9 * 1e3).abs() < 1e-5, "{ms}");
}

#[test]
fn shared_bytes_are_priced_at_the_profile_s_shared_rate() {
    // 1M invocations x 60 B = 60 MB.
    let shared = |name: &str| price_units(&prof(name), &frame(vec![staged(60.0)]))[0].clone();
    let h100 = shared("nvidia-h100");
    assert!(h100.unpriced.is_empty());
    // At the H100's probed 24 200 GB/s: 0.0024793 ms; the Switch docked's
    // 2 SMs x 128 B x 0.768 GHz = 196.6 GB/s: 0.30519 ms.
    assert!((h100.units.shared - 60e6 / 24_200e9 * 1e3).abs() < 1e-12);
    let switch = shared("switch-docked");
    assert!((switch.units.shared - 60e6 / 196.6e9 * 1e3).abs() < 1e-12);
    // shared_scale multiplies it, and it bounds the pass when slowest.
    let params = ModelParams {
        shared_scale: 2.0,
        ..ModelParams::PEAK
    };
    assert!((h100.units.scaled(&params).shared - 2.0 * 60e6 / 24_200e9 * 1e3).abs() < 1e-12);
    assert_eq!(h100.units.bound(&params), Bound::Shared);
    // Without a compute path the dispatch is a pixel shader: no shared
    // memory, nothing unpriced for want of its rate.
    let xbox = shared("xbox360");
    assert!(xbox.unpriced.is_empty(), "{:?}", xbox.unpriced);
    assert_eq!((xbox.units.shared, xbox.units.dispatch), (0.0, false));
    // A profile with compute but no known rate leaves it unpriced.
    let mut p = prof("switch-docked");
    p.alu.compute_shared_gbytes = Quantity::Unknown;
    let u = price_units(&p, &frame(vec![staged(60.0)]));
    assert_eq!(u[0].unpriced, vec!["alu.compute_shared_gbytes".to_string()]);
}

#[test]
fn a_dispatch_s_incoherent_taps_read_memory_as_coherent_ones() {
    let tap = Fetch {
        texture: "colorTex".into(),
        format: Format::Rgba16Float,
        filter: Filter::Bilinear,
        count: 10.0,
        exact: true,
        coherent: false,
        spread: Vec::new(),
    };
    let mut c = staged(0.0);
    if let Work::Compute { shader, .. } = &mut c.work {
        shader.fetches = vec![tap.clone()];
    }
    let mut d = alu_only(1_000_000, 0.0);
    if let Work::Raster {
        shader: Some(s), ..
    } = &mut d.work
    {
        s.fetches = vec![tap];
    }
    let p = prof("nvidia-h100");
    let u = price_units(&p, &frame(vec![c, d]));
    // 1M invocations: the texture once (8 B) against 10 taps x 4 texels x 8 B,
    // at 3350 GB/s (the raster pass also writes its RGBA16F target, 8 B).
    let ms = |bytes: f64| bytes / 3350e9 * 1e3;
    assert!(
        (u[0].units.memory - ms(8e6)).abs() < 1e-12,
        "{}",
        u[0].units.memory
    );
    assert!(
        (u[1].units.memory - ms(320e6 + 8e6)).abs() < 1e-12,
        "{}",
        u[1].units.memory
    );
    // The incoherent factor of dispatches applies to the dispatch only.
    let params = ModelParams {
        incoherent_factor: 3.0,
        compute_incoherent_factor: 1.5,
        ..ModelParams::PEAK
    };
    let (a, b) = (u[0].units.scaled(&params), u[1].units.scaled(&params));
    assert!((a.texture_incoherent - 1.5 * u[0].units.texture_incoherent).abs() < 1e-12);
    assert!((b.texture_incoherent - 3.0 * u[1].units.texture_incoherent).abs() < 1e-12);
}
