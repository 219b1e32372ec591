//! The cost model: per pass, the time of each unit (texture, ALU, fill, memory)
//! from the declared work and the run's counts at the profile's rates, plus the
//! costs that add up rather than overlap (clears, early rejection, geometry,
//! eDRAM resolves and restores, a fixed cost), combined by one stated rule:
//!
//! ```text
//! t = fixed + clear + max(k_tex T_tex, k_alu T_alu, k_fill T_fill, k_mem T_mem)
//!       + k_rej T_reject + T_geometry + T_resolve + T_restore
//! ```
//!
//! Units overlap (they work concurrently on different fragments), so the slowest
//! bounds the pass; what happens before the draws (clears), outside the shader
//! (rejection, setup) or after it (resolves) adds. The `k`s and the fixed cost
//! are [`ModelParams`], fitted by `calibration`, not guessed.

use serde::Serialize;

use crate::budget::edram;
use crate::budget::input::{FrameInput, PassInput, RESCALE_RULE};
use crate::budget::profile::{kebab, Profile, Quantity, TargetFormat};
use crate::graph::work::{Filter, Format, ImageUseKind, PassRole, ShaderWork, Work};

/// The model's free parameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ModelParams {
    /// Multiplies texture time (1: the profile's peak rate is reached).
    pub texture_scale: f64,
    pub alu_scale: f64,
    pub fill_scale: f64,
    pub memory_scale: f64,
    /// Multiplies the time of early-rejected pixels (at the Z-only rate).
    pub reject_scale: f64,
    /// Extra texture-time multiplier of incoherent (per-pixel rotated) taps.
    pub incoherent_factor: f64,
    /// Fixed cost of every pass, in thousands of pixels at the profile's
    /// 32 bpp fill rate (pipeline ramp-up and drain, state changes).
    pub fixed_kpix_per_pass: f64,
}

impl ModelParams {
    /// No efficiency losses, no fixed cost: the floor the profile's rates give.
    pub const PEAK: ModelParams = ModelParams {
        texture_scale: 1.0,
        alu_scale: 1.0,
        fill_scale: 1.0,
        memory_scale: 1.0,
        reject_scale: 1.0,
        incoherent_factor: 1.0,
        fixed_kpix_per_pass: 0.0,
    };

    /// The parameters fitted on every calibration point
    /// (`calibration::fit_all`; docs/budget-calibration.md lists them and
    /// the held-out errors).
    pub fn fitted() -> ModelParams {
        crate::budget::calibration::FITTED
    }

    /// The parameters as a vector (for fitting) and back.
    pub fn to_vec(self) -> [f64; 7] {
        [
            self.texture_scale,
            self.alu_scale,
            self.fill_scale,
            self.memory_scale,
            self.reject_scale,
            self.incoherent_factor,
            self.fixed_kpix_per_pass,
        ]
    }

    pub fn from_vec(v: [f64; 7]) -> ModelParams {
        ModelParams {
            texture_scale: v[0],
            alu_scale: v[1],
            fill_scale: v[2],
            memory_scale: v[3],
            reject_scale: v[4],
            incoherent_factor: v[5],
            fixed_kpix_per_pass: v[6],
        }
    }
}

/// Which unit bounds a pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Bound {
    Texture,
    Alu,
    Fill,
    Memory,
    /// eDRAM resolves and restores outweigh the shading.
    Resolve,
    /// Clears, rejection, setup or the fixed cost outweigh the shading.
    Overhead,
}

/// Unit times of a pass before the parameters apply, in ms.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct UnitTimes {
    pub texture: f64,
    /// Texture time of incoherent taps (scaled by `incoherent_factor` too).
    pub texture_incoherent: f64,
    pub alu: f64,
    pub fill: f64,
    pub memory: f64,
    pub reject: f64,
    pub clear: f64,
    pub geometry: f64,
    pub resolve: f64,
    pub restore: f64,
    /// ms of 1000 pixels at the profile's 32 bpp fill rate.
    pub fixed_unit: f64,
}

impl UnitTimes {
    /// The combining rule (module docs).
    pub fn combine(&self, p: &ModelParams) -> f64 {
        let (shading, _) = self.shading(p);
        p.fixed_kpix_per_pass * self.fixed_unit
            + p.fill_scale * self.clear
            + shading
            + p.reject_scale * self.reject
            + self.geometry
            + self.resolve
            + self.restore
    }

    fn shading(&self, p: &ModelParams) -> (f64, Bound) {
        let tex = p.texture_scale * (self.texture + p.incoherent_factor * self.texture_incoherent);
        let units = [
            (tex, Bound::Texture),
            (p.alu_scale * self.alu, Bound::Alu),
            (p.fill_scale * self.fill, Bound::Fill),
            (p.memory_scale * self.memory, Bound::Memory),
        ];
        units
            .into_iter()
            .fold((0.0, Bound::Fill), |a, u| if u.0 > a.0 { u } else { a })
    }

    fn bound(&self, p: &ModelParams) -> Bound {
        let (shading, b) = self.shading(p);
        let overhead = p.fixed_kpix_per_pass * self.fixed_unit
            + p.fill_scale * self.clear
            + p.reject_scale * self.reject
            + self.geometry;
        let resolve = self.resolve + self.restore;
        if resolve > shading && resolve >= overhead {
            Bound::Resolve
        } else if overhead > shading {
            Bound::Overhead
        } else {
            b
        }
    }
}

/// A format the profile cannot render (or blend), and what was priced instead.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Substitution {
    pub wanted: String,
    pub used: Option<String>,
    pub reason: String,
    /// Fill time of the substitute's writes in this pass (unscaled).
    pub fill_ms: Option<f64>,
}

/// One eDRAM resolve (or restore: main memory back into eDRAM).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Transfer {
    pub image: String,
    pub bytes: u64,
    pub ms: Option<f64>,
    /// The pass whose read forced it.
    pub forced_by: String,
}

/// How a pass uses eDRAM.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct EdramUse {
    /// Tiles its colour and depth targets take at full screen.
    pub footprint_tiles: u32,
    /// Screen tiles: 1 fits; more means predicated tiling.
    pub screen_tiles: u32,
    pub predicated_tiling: bool,
    pub resolves: Vec<Transfer>,
    pub restores: Vec<Transfer>,
}

/// Unit times of a pass with what could not be priced.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PassUnits {
    pub name: String,
    pub role: PassRole,
    pub units: UnitTimes,
    pub edram: Option<EdramUse>,
    pub substitutions: Vec<Substitution>,
    /// Quantities the profile lacks that this pass needs.
    pub unpriced: Vec<String>,
    /// MRT or MSAA limits exceeded, targets that never fit eDRAM.
    pub overruns: Vec<String>,
    pub measured_ms: Option<f64>,
}

impl PassUnits {
    pub fn modelled_ms(&self, p: &ModelParams) -> Option<f64> {
        self.unpriced.is_empty().then(|| self.units.combine(p))
    }
}

/// Per-pass result, ready for JSON.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PassBudget {
    pub name: String,
    pub role: PassRole,
    pub modelled_ms: Option<f64>,
    pub measured_ms: Option<f64>,
    pub bound: Option<Bound>,
    /// Each term of the combining rule, parameters applied (ms).
    pub terms_ms: UnitTimes,
    pub edram: Option<EdramUse>,
    pub substitutions: Vec<Substitution>,
    pub unpriced: Vec<String>,
    pub overruns: Vec<String>,
    pub share_of_frame: Option<f64>,
    /// For SSS passes: share of the profile's skin-SSS budget.
    pub share_of_skin_budget: Option<f64>,
}

/// Time of one role against its budget.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CategoryBudget {
    pub role: PassRole,
    pub modelled_ms: f64,
    pub budget_ms: f64,
    pub over: bool,
}

/// The whole frame on one profile.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FrameBudget {
    pub profile: String,
    pub label: String,
    /// Size of the run the counts come from.
    pub run_size: [u32; 2],
    /// Size the frame was priced at.
    pub priced_size: [u32; 2],
    pub rescale_rule: Option<String>,
    pub params: ModelParams,
    pub passes: Vec<PassBudget>,
    /// Sum over priced frame-cost passes.
    pub total_ms: f64,
    pub measured_total_ms: Option<f64>,
    pub frame_ms: f64,
    pub over_frame: bool,
    pub skin_budget_ms: f64,
    pub sss_ms: f64,
    pub over_skin_budget: bool,
    pub categories: Vec<CategoryBudget>,
    pub unpriced_passes: Vec<String>,
    pub substitutions: usize,
    pub overruns: Vec<String>,
}

/// At which resolution to price.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rescale {
    /// The run's own resolution.
    AsRun,
    /// The profile's target resolution (see `input::RESCALE_RULE`).
    ToProfile,
}

/// Looks up a quantity, recording it as missing when unknown.
struct Need<'a> {
    missing: &'a mut Vec<String>,
}

impl Need<'_> {
    fn get(&mut self, what: &str, q: Quantity) -> Option<f64> {
        let v = q.value();
        if v.is_none() && !self.missing.iter().any(|m| m == what) {
            self.missing.push(what.to_string());
        }
        v
    }
}

const G: f64 = 1e9;
const MS: f64 = 1e3;

/// The format used on this profile for a target of `wanted` (itself when it
/// can render it, and blend it when `blend`), recording substitutions.
fn target_format(
    prof: &Profile,
    wanted: Format,
    blend: bool,
    subs: &mut Vec<Substitution>,
) -> Option<TargetFormat> {
    let w = TargetFormat::from_work(wanted);
    let ok = |c: &crate::budget::profile::FormatCaps| c.render && (!blend || c.blend);
    match prof.caps(w) {
        Some(c) if ok(c) => return Some(w),
        _ => {}
    }
    let reason = match prof.caps(w) {
        None => "not listed by the profile",
        Some(c) if !c.render => "cannot be rendered",
        Some(_) => "cannot be blended",
    };
    let used = prof
        .formats
        .iter()
        .filter(|c| ok(c))
        .min_by(|a, b| {
            a.format
                .distance_from(w)
                .total_cmp(&b.format.distance_from(w))
        })
        .map(|c| c.format);
    if !subs.iter().any(|s| s.wanted == kebab(w)) {
        subs.push(Substitution {
            wanted: kebab(w),
            used: used.map(kebab),
            reason: format!("{} {reason}", kebab(w)),
            fill_ms: None,
        });
    }
    used
}

/// Format of a copy or clear of `bpp` bytes per texel when no image names it.
fn format_of_bpp(bpp: u32) -> Format {
    match bpp {
        0..=2 => Format::R16Float,
        3..=4 => Format::Rgba8Unorm,
        5..=8 => Format::Rgba16Float,
        _ => Format::Rgba32Float,
    }
}

fn texel_cost(prof: &Profile, need: &mut Need, filter: Filter, format: Format) -> Option<f64> {
    let t = &prof.texture;
    let f = match filter {
        Filter::Point => need.get("texture.point_cost", t.point_cost)?,
        Filter::Bilinear => 1.0,
        Filter::Trilinear => need.get("texture.trilinear_cost", t.trilinear_cost)?,
        Filter::DepthCompare => need.get("texture.depth_compare_cost", t.depth_compare_cost)?,
    };
    let b = match format.bytes_per_texel() {
        0..=4 => 1.0,
        5..=8 => need.get("texture.texel_64bpp_cost", t.texel_64bpp_cost)?,
        _ => need.get("texture.texel_128bpp_cost", t.texel_128bpp_cost)?,
    };
    Some(f * b)
}

/// Texture, ALU and texture-memory terms of `n` invocations of `s`.
fn shader_terms(
    prof: &Profile,
    need: &mut Need,
    s: &ShaderWork,
    n: f64,
    compute: bool,
    incoherent: &[String],
    u: &mut UnitTimes,
) {
    let rate = if s.fetches.is_empty() {
        None
    } else if compute {
        need.get(
            "texture.compute_bilinear_gtexels",
            prof.texture.compute_bilinear_gtexels,
        )
    } else {
        need.get("texture.bilinear_gtexels", prof.texture.bilinear_gtexels)
    };
    let mut seen: Vec<&str> = Vec::new();
    for f in &s.fetches {
        if let (Some(r), Some(c)) = (rate, texel_cost(prof, need, f.filter, f.format)) {
            let ms = n * f.count * c / (r * G) * MS;
            if incoherent.iter().any(|t| t == &f.texture) {
                u.texture_incoherent += ms;
            } else {
                u.texture += ms;
            }
        }
        // Memory: each texture's footprint is read about once per fragment
        // (neighbouring taps hit the cache); incoherent taps read 4 texels each.
        let bpt = f64::from(f.format.bytes_per_texel());
        if incoherent.iter().any(|t| t == &f.texture) {
            u.memory += n * f.count * 4.0 * bpt;
        } else if !seen.contains(&f.texture.as_str()) {
            seen.push(&f.texture);
            u.memory += n * bpt;
        }
    }
    u.memory += n * (s.storage_read_bytes + s.storage_write_bytes);
    let gflops = if compute {
        need.get("alu.compute_gflops", prof.alu.compute_gflops)
    } else {
        need.get("alu.gflops", prof.alu.gflops)
    };
    if let Some(g) = gflops {
        // An arithmetic instruction per lane per clock; peak GFLOPS count a
        // multiply-add as two.
        u.alu = n * s.alu / (g / 2.0 * G) * MS;
    }
}

/// Fill rate of a format (its blend rate when blending).
fn fill_rate(prof: &Profile, need: &mut Need, f: TargetFormat, blend: bool) -> Option<f64> {
    let c = prof.caps(f)?;
    let (q, what) = if blend {
        (c.blend_gpix, format!("formats.{}.blend_gpix", kebab(f)))
    } else {
        (c.fill_gpix, format!("formats.{}.fill_gpix", kebab(f)))
    };
    need.get(&what, q)
}

fn fixed_unit(prof: &Profile, need: &mut Need) -> f64 {
    let r = prof
        .caps(TargetFormat::Rgba8Unorm)
        .and_then(|c| c.fill_gpix.value())
        .or_else(|| {
            prof.formats
                .iter()
                .find(|c| {
                    c.format.bytes() == 4
                        && c.format.class() != crate::budget::profile::FormatClass::Depth
                })
                .and_then(|c| c.fill_gpix.value())
        });
    match r {
        Some(r) => 1000.0 / (r * G) * MS,
        None => {
            need.get("formats.rgba8-unorm.fill_gpix", Quantity::Unknown);
            0.0
        }
    }
}

/// Prices one pass's units, ignoring eDRAM transfers (added by [`price_units`]).
fn pass_units(prof: &Profile, p: &PassInput) -> PassUnits {
    let mut missing = Vec::new();
    let mut subs = Vec::new();
    let mut overruns = Vec::new();
    let mut u = UnitTimes::default();
    let mut edram_use = None;
    {
        let mut need = Need {
            missing: &mut missing,
        };
        u.fixed_unit = fixed_unit(prof, &mut need);
        let on_edram = prof.edram.as_ref();
        let mem_bw = need.get("memory.bandwidth_gbps", prof.memory.bandwidth_gbps);
        let z_rate = need.get("raster.z_only_gsamples", prof.raster.z_only_gsamples);
        let mut mem_bytes = 0.0;

        // Clears at the start of the pass: in eDRAM at its internal rate,
        // elsewhere at the format's fill rate.
        for c in &p.clears {
            let bytes = c.texels as f64 * f64::from(c.format.bytes_per_texel());
            match on_edram {
                Some(e) => {
                    if let Some(r) = need.get("edram.internal_gbps", e.internal_gbps) {
                        u.clear += bytes / (r * G) * MS;
                    }
                }
                None => {
                    let f = target_format(prof, c.format, false, &mut subs);
                    let r = f.and_then(|f| fill_rate(prof, &mut need, f, false));
                    if let Some(r) = r {
                        u.clear += c.texels as f64 / (r * G) * MS;
                    } else if f.is_none() {
                        need.get(
                            &format!(
                                "a renderable format for {}",
                                kebab(TargetFormat::from_work(c.format))
                            ),
                            Quantity::Unknown,
                        );
                    }
                    mem_bytes += bytes;
                }
            }
        }

        match &p.work {
            Work::Raster {
                shader,
                color,
                depth_stencil,
                width,
                height,
                triangles,
                msaa,
            } => {
                let n = p.fragments as f64;
                let msaa = (*msaa).max(1);
                if let Some(s) = shader {
                    shader_terms(prof, &mut need, s, n, false, &p.incoherent_textures, &mut u);
                }
                if msaa > prof.raster.max_msaa {
                    overruns.push(format!(
                        "{msaa}x MSAA, the profile allows {}x",
                        prof.raster.max_msaa
                    ));
                }
                let splits = color
                    .len()
                    .div_ceil(prof.raster.max_color_targets as usize)
                    .max(1);
                if splits > 1 {
                    overruns.push(format!(
                        "writes {} colour targets, the profile allows {}: split into {splits} passes",
                        color.len(),
                        prof.raster.max_color_targets
                    ));
                }
                let mut target_bytes: Vec<u32> = Vec::new();
                for cw in color {
                    let f = target_format(prof, cw.format, cw.blend, &mut subs);
                    let Some(f) = f else {
                        need.get(
                            &format!(
                                "a renderable format for {}",
                                kebab(TargetFormat::from_work(cw.format))
                            ),
                            Quantity::Unknown,
                        );
                        continue;
                    };
                    target_bytes.push(f.bytes());
                    let mut t = fill_rate(prof, &mut need, f, cw.blend).map(|r| n / (r * G) * MS);
                    if msaa > 1 {
                        let ms = need
                            .get("raster.msaa_gsamples", prof.raster.msaa_gsamples)
                            .map(|r| n * f64::from(msaa) / (r * G) * MS);
                        t = match (t, ms) {
                            (Some(a), Some(b)) => Some(a.max(b)),
                            _ => None,
                        };
                    }
                    if let Some(t) = t {
                        u.fill += t;
                        if let Some(s) = subs
                            .iter_mut()
                            .find(|s| s.wanted == kebab(TargetFormat::from_work(cw.format)))
                        {
                            *s.fill_ms.get_or_insert(0.0) += t;
                        }
                    }
                    let rw = if cw.blend { 2.0 } else { 1.0 };
                    if on_edram.is_none() {
                        mem_bytes += n * f64::from(msaa) * f64::from(f.bytes()) * rw;
                    }
                }
                let passed = p.samples_passed as f64;
                if let Some(ds) = depth_stencil {
                    let f = target_format(prof, ds.format, false, &mut subs);
                    if let Some(f) = f {
                        target_bytes.push(f.bytes());
                        if on_edram.is_none() {
                            let rw = f64::from(u8::from(ds.depth_test || ds.stencil_test))
                                + f64::from(u8::from(ds.depth_write || ds.stencil_write));
                            mem_bytes +=
                                n.max(passed) * f64::from(msaa) * f64::from(f.bytes()) * rw;
                        }
                    }
                    // A depth-only pass is bound by its Z writes.
                    if color.is_empty() {
                        if let Some(z) = z_rate {
                            u.fill += passed * f64::from(msaa) / (z * G) * MS;
                        }
                    }
                }
                // Early rejection: covered pixels the tests discard.
                let shaded = if shader.is_some() && !color.is_empty() {
                    n
                } else {
                    passed
                };
                if let (Some(r), Some(z)) = (p.rasterized_pixels, z_rate) {
                    let rejected = (r as f64 - shaded).max(0.0);
                    u.reject = rejected * f64::from(msaa) / (z * G) * MS;
                }
                let mut geo_factor = splits as f64;
                if let Some(e) = on_edram {
                    let st = edram::screen_tiles(*width, *height, msaa, &target_bytes, e);
                    let footprint: u32 = target_bytes
                        .iter()
                        .map(|&b| edram::surface_tiles(*width, *height, msaa, b, e))
                        .sum();
                    let st = match st {
                        Some(s) => s,
                        None => {
                            overruns.push("one row of tiles does not fit in eDRAM".into());
                            1
                        }
                    };
                    if st > 1 {
                        if let Some(f) =
                            need.get("edram.tiled_geometry_factor", e.tiled_geometry_factor)
                        {
                            geo_factor *= f;
                        }
                    }
                    edram_use = Some(EdramUse {
                        footprint_tiles: footprint,
                        screen_tiles: st,
                        predicated_tiling: st > 1,
                        ..Default::default()
                    });
                }
                if *triangles > 0 {
                    if let Some(r) = need.get("raster.triangles_gtris", prof.raster.triangles_gtris)
                    {
                        u.geometry = *triangles as f64 * geo_factor / (r * G) * MS;
                    }
                }
            }
            Work::Compute {
                shader,
                invocations,
            } => {
                shader_terms(
                    prof,
                    &mut need,
                    shader,
                    *invocations as f64,
                    true,
                    &p.incoherent_textures,
                    &mut u,
                );
            }
            Work::Copy {
                texels,
                bytes_per_texel,
            } => {
                let fmt = p
                    .images
                    .iter()
                    .find(|i| i.kind == ImageUseKind::CopyDestination)
                    .or_else(|| p.images.first())
                    .map(|i| i.format)
                    .unwrap_or_else(|| format_of_bpp(*bytes_per_texel));
                let n = *texels as f64;
                let bytes = n * f64::from(*bytes_per_texel);
                let f = target_format(prof, fmt, false, &mut subs);
                if let Some(r) = f.and_then(|f| fill_rate(prof, &mut need, f, false)) {
                    // Copies go through the pixel pipeline (a draw on eDRAM
                    // consoles, the copy path elsewhere): one texel per pixel.
                    u.fill += n / (r * G) * MS;
                }
                match on_edram {
                    Some(e) => {
                        // Read as a texture, drawn into eDRAM, resolved out.
                        if let (Some(r), Some(c)) = (
                            need.get("texture.bilinear_gtexels", prof.texture.bilinear_gtexels),
                            texel_cost(prof, &mut need, Filter::Point, fmt),
                        ) {
                            u.texture += n * c / (r * G) * MS;
                        }
                        mem_bytes += bytes;
                        if let Some(r) = need.get("edram.resolve_gbps", e.resolve_gbps) {
                            u.resolve += bytes / (r * G) * MS;
                        }
                    }
                    None => mem_bytes += 2.0 * bytes,
                }
            }
            Work::Clear {
                texels,
                bytes_per_texel,
            } => {
                let bytes = *texels as f64 * f64::from(*bytes_per_texel);
                match on_edram {
                    Some(e) => {
                        if let Some(r) = need.get("edram.internal_gbps", e.internal_gbps) {
                            u.clear += bytes / (r * G) * MS;
                        }
                    }
                    None => {
                        let fmt = p
                            .images
                            .first()
                            .map(|i| i.format)
                            .unwrap_or_else(|| format_of_bpp(*bytes_per_texel));
                        let f = target_format(prof, fmt, false, &mut subs);
                        if let Some(r) = f.and_then(|f| fill_rate(prof, &mut need, f, false)) {
                            u.clear += *texels as f64 / (r * G) * MS;
                        }
                        mem_bytes += bytes;
                    }
                }
            }
        }
        if let Some(bw) = mem_bw {
            u.memory = (u.memory + mem_bytes) / (bw * G) * MS;
        } else {
            u.memory = 0.0;
        }
    }
    PassUnits {
        name: p.name.clone(),
        role: p.role,
        units: u,
        edram: edram_use,
        substitutions: subs,
        unpriced: missing,
        overruns,
        measured_ms: p.measured_ms,
    }
}

fn writes(kind: ImageUseKind) -> bool {
    matches!(
        kind,
        ImageUseKind::ColorTarget | ImageUseKind::ColorTargetLoad | ImageUseKind::DepthTarget
    )
}

fn loads(kind: ImageUseKind) -> bool {
    matches!(
        kind,
        ImageUseKind::ColorTargetLoad | ImageUseKind::DepthTest
    )
}

fn reads_as_texture(kind: ImageUseKind) -> bool {
    matches!(
        kind,
        ImageUseKind::Sampled
            | ImageUseKind::CopySource
            | ImageUseKind::Host
            | ImageUseKind::Storage
    )
}

/// Unit times of every pass of a frame on a profile, with eDRAM resolves and
/// restores: a render target later sampled, copied or read back is resolved
/// once after its last write before that read (charged to the writing pass);
/// a pass that loads a target (blends into it, tests against its depth) must
/// find it in eDRAM, which holds only the previous draw pass's targets, and
/// only when neither pass was tiled; otherwise the target is restored from
/// main memory (a full-screen copy in, charged to the loading pass).
pub fn price_units(prof: &Profile, frame: &FrameInput) -> Vec<PassUnits> {
    let mut out: Vec<PassUnits> = frame.passes.iter().map(|p| pass_units(prof, p)).collect();
    let Some(e) = prof.edram.as_ref() else {
        return out;
    };
    let resolve_rate = e.resolve_gbps.value();
    let mem_rate = prof.memory.bandwidth_gbps.value();
    let is_draw = |p: &PassInput| matches!(p.work, Work::Raster { .. });
    // Per image: the pass that last wrote it into eDRAM and whether that
    // write has been resolved since.
    let mut last_write: std::collections::HashMap<&str, (usize, bool)> = Default::default();
    let mut prev_draw: Option<usize> = None;
    for (j, p) in frame.passes.iter().enumerate() {
        // Reads of earlier eDRAM writes force their resolve.
        let force =
            |img: &str,
             fmt: Format,
             w: u32,
             h: u32,
             out: &mut Vec<PassUnits>,
             last: &mut std::collections::HashMap<&str, (usize, bool)>| {
                if let Some((i, resolved)) = last.get_mut(img) {
                    if !*resolved && *i != j {
                        *resolved = true;
                        let bytes =
                            edram::resolve_bytes(w, h, TargetFormat::from_work(fmt).bytes());
                        let ms = resolve_rate.map(|r| bytes as f64 / (r * G) * MS);
                        let pu = &mut out[*i];
                        match ms {
                            Some(ms) => pu.units.resolve += ms,
                            None => {
                                if !pu.unpriced.iter().any(|m| m == "edram.resolve_gbps") {
                                    pu.unpriced.push("edram.resolve_gbps".into());
                                }
                            }
                        }
                        if let Some(eu) = pu.edram.as_mut() {
                            eu.resolves.push(Transfer {
                                image: img.to_string(),
                                bytes,
                                ms,
                                forced_by: p.name.clone(),
                            });
                        }
                    }
                }
            };
        for iu in &p.images {
            if reads_as_texture(iu.kind) {
                force(
                    &iu.image,
                    iu.format,
                    iu.width,
                    iu.height,
                    &mut out,
                    &mut last_write,
                );
            }
        }
        if is_draw(p) {
            let tiles: Vec<bool> = out
                .iter()
                .map(|u| u.edram.as_ref().is_some_and(|x| x.screen_tiles > 1))
                .collect();
            for iu in p.images.iter().filter(|iu| loads(iu.kind)) {
                let resident = prev_draw.is_some_and(|k| {
                    !tiles[k]
                        && !tiles[j]
                        && frame.passes[k]
                            .images
                            .iter()
                            .any(|x| x.image == iu.image && (writes(x.kind) || loads(x.kind)))
                });
                if resident {
                    continue;
                }
                // Its contents must reach main memory first.
                force(
                    &iu.image,
                    iu.format,
                    iu.width,
                    iu.height,
                    &mut out,
                    &mut last_write,
                );
                let bytes = edram::resolve_bytes(
                    iu.width,
                    iu.height,
                    TargetFormat::from_work(iu.format).bytes(),
                );
                let ms = mem_rate.map(|r| bytes as f64 / (r * G) * MS);
                let pu = &mut out[j];
                if let Some(ms) = ms {
                    pu.units.restore += ms;
                }
                if let Some(eu) = pu.edram.as_mut() {
                    eu.restores.push(Transfer {
                        image: iu.image.clone(),
                        bytes,
                        ms,
                        forced_by: p.name.clone(),
                    });
                }
            }
            prev_draw = Some(j);
        } else {
            // A copy or clear draws through eDRAM too: nothing stays resident.
            prev_draw = None;
        }
        for iu in &p.images {
            if writes(iu.kind) && is_draw(p) {
                last_write.insert(iu.image.as_str(), (j, false));
            }
        }
    }
    out
}

/// Prices a frame on a profile: the call behind `dermis budget`.
pub fn price_frame(
    prof: &Profile,
    frame: &FrameInput,
    params: &ModelParams,
    rescale: Rescale,
) -> FrameBudget {
    let (w, h) = (prof.target.width_px, prof.target.height_px);
    let scaled;
    let (priced, rule) = match rescale {
        Rescale::ToProfile if (w, h) != (frame.width, frame.height) => {
            scaled = frame.rescaled(w, h);
            (&scaled, Some(RESCALE_RULE.to_string()))
        }
        _ => (frame, None),
    };
    let units = price_units(prof, priced);
    let frame_ms = prof.target.frame_ms;
    let skin_budget_ms = prof.share_ms(prof.budget.sss_share);
    let mut passes = Vec::new();
    let mut total = 0.0;
    let mut measured = 0.0;
    let mut all_measured = true;
    let mut unpriced_passes = Vec::new();
    let mut overruns = Vec::new();
    let mut by_role: Vec<(PassRole, f64)> = Vec::new();
    for (pu, pin) in units.iter().zip(&priced.passes) {
        let modelled = pu.modelled_ms(params);
        let cost = pin.role.is_frame_cost();
        if cost {
            match modelled {
                Some(m) => {
                    total += m;
                    match by_role.iter_mut().find(|r| r.0 == pin.role) {
                        Some(r) => r.1 += m,
                        None => by_role.push((pin.role, m)),
                    }
                }
                None => {
                    unpriced_passes.push(format!("{}: needs {}", pu.name, pu.unpriced.join(", ")))
                }
            }
            match pin.measured_ms {
                Some(m) => measured += m,
                None => all_measured = false,
            }
        }
        for o in &pu.overruns {
            overruns.push(format!("{}: {o}", pu.name));
        }
        let u = &pu.units;
        let terms = UnitTimes {
            texture: params.texture_scale * u.texture,
            texture_incoherent: params.texture_scale
                * params.incoherent_factor
                * u.texture_incoherent,
            alu: params.alu_scale * u.alu,
            fill: params.fill_scale * u.fill,
            memory: params.memory_scale * u.memory,
            reject: params.reject_scale * u.reject,
            clear: params.fill_scale * u.clear,
            geometry: u.geometry,
            resolve: u.resolve,
            restore: u.restore,
            fixed_unit: params.fixed_kpix_per_pass * u.fixed_unit,
        };
        passes.push(PassBudget {
            name: pu.name.clone(),
            role: pu.role,
            modelled_ms: modelled,
            measured_ms: pu.measured_ms,
            bound: modelled.map(|_| u.bound(params)),
            terms_ms: terms,
            edram: pu.edram.clone(),
            substitutions: pu.substitutions.clone(),
            unpriced: pu.unpriced.clone(),
            overruns: pu.overruns.clone(),
            share_of_frame: modelled.filter(|_| cost).map(|m| m / frame_ms),
            share_of_skin_budget: modelled
                .filter(|_| pin.role == PassRole::Sss)
                .map(|m| m / skin_budget_ms),
        });
    }
    let share = |r: PassRole| match r {
        PassRole::Shadow => prof.budget.shadow_share,
        PassRole::Geometry => prof.budget.geometry_share,
        PassRole::Sss => prof.budget.sss_share,
        PassRole::Post => prof.budget.post_share,
        _ => 0.0,
    };
    let categories: Vec<CategoryBudget> = by_role
        .iter()
        .map(|&(role, ms)| {
            let budget_ms = prof.share_ms(share(role));
            CategoryBudget {
                role,
                modelled_ms: ms,
                budget_ms,
                over: ms > budget_ms,
            }
        })
        .collect();
    let sss_ms = by_role
        .iter()
        .find(|r| r.0 == PassRole::Sss)
        .map_or(0.0, |r| r.1);
    let substitutions = passes.iter().map(|p| p.substitutions.len()).sum();
    FrameBudget {
        profile: prof.profile.name.clone(),
        label: frame.label.clone(),
        run_size: [frame.width, frame.height],
        priced_size: [priced.width, priced.height],
        rescale_rule: rule,
        params: *params,
        passes,
        total_ms: total,
        measured_total_ms: (all_measured && rescale == Rescale::AsRun).then_some(measured),
        frame_ms,
        over_frame: total > frame_ms,
        skin_budget_ms,
        sss_ms,
        over_skin_budget: sss_ms > skin_budget_ms,
        categories,
        unpriced_passes,
        substitutions,
        overruns,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::budget::frames;
    use crate::graph::work::{ColorWrite, Fetch, ImageUse};

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
            *depth_stencil = Some(crate::graph::work::DepthStencilUse {
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

    #[test]
    fn missing_numbers_leave_the_pass_unpriced_and_named() {
        // The Xbox 360 has no compute path: a dispatch cannot be priced.
        let p = prof("xbox360");
        let c = PassInput::new(
            "gather",
            PassRole::Sss,
            Work::Compute {
                shader: ShaderWork {
                    alu: 10.0,
                    ..Default::default()
                },
                invocations: 1000,
            },
        );
        let b = price_frame(
            &p,
            &frame(vec![c, blur(1000, 1.0)]),
            &ModelParams::PEAK,
            Rescale::AsRun,
        );
        assert_eq!(b.passes[0].modelled_ms, None);
        assert_eq!(b.passes[0].unpriced, vec!["alu.compute_gflops".to_string()]);
        assert_eq!(b.unpriced_passes.len(), 1);
        assert!(b.unpriced_passes[0].starts_with("gather"));
        assert!(b.passes[1].modelled_ms.is_some());
    }

    #[test]
    fn every_pass_of_every_method_is_priced_on_the_xbox_360() {
        let p = prof("xbox360");
        for f in frames::h100_frames().unwrap() {
            let b = price_frame(&p, &f.frame, &ModelParams::fitted(), Rescale::ToProfile);
            assert!(
                b.unpriced_passes.is_empty(),
                "{}: {:?}",
                f.frame.label,
                b.unpriced_passes
            );
            assert_eq!(b.priced_size, [1280, 720]);
            assert!(b.total_ms > 0.0 && b.passes.iter().all(|p| p.modelled_ms.is_some()));
            // Every SSS method samples a target another pass drew: resolves happen.
            assert!(b
                .passes
                .iter()
                .any(|p| p.edram.as_ref().is_some_and(|e| !e.resolves.is_empty())));
        }
    }

    #[test]
    fn frame_budget_serialises() {
        let p = prof("xbox360");
        let f = &frames::h100_frames().unwrap()[0];
        let b = price_frame(&p, &f.frame, &ModelParams::fitted(), Rescale::ToProfile);
        let j = serde_json::to_string(&b).unwrap();
        for key in [
            "\"modelled_ms\"",
            "\"bound\"",
            "\"screen_tiles\"",
            "\"resolves\"",
            "\"share_of_skin_budget\"",
            "\"over_frame\"",
        ] {
            assert!(j.contains(key), "{key} missing");
        }
    }
}
