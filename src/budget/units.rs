//! Unit times of one pass on a profile: texture, ALU, fill, memory, and the
//! costs that add rather than overlap (clears, early rejection, geometry set-up,
//! per-rectangle copy costs; eDRAM resolves and restores are added over the
//! whole frame by `transfers`), and how they combine:
//!
//! ```text
//! t = fixed + k_rect rects + k_fill T_clear
//!       + max(k_tex (T_tex + f_inc T_tex_incoherent), k_alu T_alu, k_fill T_fill, k_mem T_mem,
//!             k_shared T_shared)
//!       + k_rej T_reject + k_hiz T_reject_hiz + T_geometry + T_resolve + T_restore
//! ```
//!
//! A dispatch (and a transfer outside a render pass, a buffer fill) takes
//! `fixed` at `fixed_kpix_per_dispatch`, its ALU at `compute_alu_scale` and
//! its incoherent taps at `compute_incoherent_factor`, and its incoherent
//! taps' memory traffic as its coherent taps' (each texture's footprint once
//! an invocation: the H100 took the gather's rotated taps at its coherent
//! rate, over images its 50 MB L2 holds); `T_shared` is its workgroup
//! shared-memory bytes over the profile's shared-memory rate, scaled by
//! `shared_scale` (`ModelParams::shared_scale` says what it prices).
//!
//! Units overlap (they work concurrently on different fragments), so the
//! slowest bounds the pass; what happens before the draws (clears), outside
//! the shader (rejection, set-up) or after it (resolves) adds. The `k`s,
//! `f_inc` and the fixed costs are [`ModelParams`], fitted by `calibration`.
//! The ALU unit is instructions over the profile's issue rate
//! ([`crate::budget::profile::Alu::ginstr`]: lane-instructions on SIMT
//! GPUs, whole vector instructions on Xenos and RSX).
//! (A p-norm of the unit times in place of their maximum, p fitted, gained
//! 1 point of median error on the H100 and destabilised the published fit:
//! not kept.)

use serde::Serialize;

use crate::budget::edram;
use crate::budget::input::PassInput;
use crate::budget::msaa::{self, Coverage};
use crate::budget::params::ModelParams;
use crate::budget::profile::{
    kebab, FormatCaps, FormatClass, MsaaCompression, Profile, Quantity, TargetFormat,
};
use crate::work::{
    ColorWrite, DepthStencilUse, Filter, Format, ImageUseKind, PassRole, ShaderWork, Work,
};

const G: f64 = 1e9;
const MS: f64 = 1e3;

use crate::budget::unit_times::add_spread;
pub use crate::budget::unit_times::{spread_bin_radius, Bound, UnitTimes, SPREAD_BINS};

/// A format (or a path) the profile lacks, and what was priced instead.
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

/// Prices one pass's units (eDRAM transfers are added by `transfers`).
pub fn pass_units(prof: &Profile, p: &PassInput) -> PassUnits {
    let mut s = Pricing {
        prof,
        missing: Vec::new(),
        subs: Vec::new(),
        overruns: Vec::new(),
        u: UnitTimes::default(),
        mem_bytes: 0.0,
        edram: None,
    };
    s.u.fixed_unit = s.fixed_unit();
    match &p.work {
        Work::Raster { .. } => s.raster(p),
        Work::Compute {
            shader,
            invocations,
        } => s.compute(shader, *invocations as f64),
        Work::Copy {
            texels,
            bytes_per_texel,
            rects,
        } => s.copy(p, *texels, *bytes_per_texel, *rects),
        Work::Clear {
            texels,
            bytes_per_texel,
        } => s.clear_pass(p, *texels, *bytes_per_texel),
    }
    let bw = s.need("memory.bandwidth_gbps", prof.memory.bandwidth_gbps);
    s.u.memory = bw.map_or(0.0, |bw| (s.u.memory + s.mem_bytes) / (bw * G) * MS);
    PassUnits {
        name: p.name.clone(),
        role: p.role,
        units: s.u,
        edram: s.edram,
        substitutions: s.subs,
        unpriced: s.missing,
        overruns: s.overruns,
        measured_ms: p.measured_ms,
    }
}

/// The format a target of `wanted` is priced in on `prof`: itself when the
/// profile can render it (and blend it when `blend`), else the nearest one it
/// can (`TargetFormat::distance_from`).
pub fn priced_format(prof: &Profile, wanted: Format, blend: bool) -> Option<TargetFormat> {
    let w = TargetFormat::from_work(wanted);
    let ok = |c: &FormatCaps| c.render && (!blend || c.blend);
    if prof.caps(w).is_some_and(ok) {
        return Some(w);
    }
    prof.formats
        .iter()
        .filter(|c| ok(c))
        .min_by(|a, b| {
            a.format
                .distance_from(w)
                .total_cmp(&b.format.distance_from(w))
        })
        .map(|c| c.format)
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

/// The state of pricing one pass. `u.memory` collects texture bytes and
/// `mem_bytes` render-target bytes until both are turned into time.
struct Pricing<'a> {
    prof: &'a Profile,
    missing: Vec<String>,
    subs: Vec<Substitution>,
    overruns: Vec<String>,
    u: UnitTimes,
    mem_bytes: f64,
    edram: Option<EdramUse>,
}

impl Pricing<'_> {
    /// A quantity's value, recording it as missing when unknown.
    fn need(&mut self, what: &str, q: Quantity) -> Option<f64> {
        let v = q.value();
        if v.is_none() && !self.missing.iter().any(|m| m == what) {
            self.missing.push(what.to_string());
        }
        v
    }

    fn fixed_unit(&mut self) -> f64 {
        let prof = self.prof;
        let r = prof
            .caps(TargetFormat::Rgba8Unorm)
            .and_then(|c| c.fill_gpix.value())
            .or_else(|| {
                prof.formats
                    .iter()
                    .find(|c| c.format.bytes() == 4 && c.format.class() != FormatClass::Depth)
                    .and_then(|c| c.fill_gpix.value())
            });
        match r {
            Some(r) => 1000.0 / (r * G) * MS,
            None => {
                self.need("formats.rgba8-unorm.fill_gpix", Quantity::Unknown);
                0.0
            }
        }
    }

    /// The format used on this profile for a target of `wanted` (itself when
    /// it can render it, and blend it when `blend`), recording substitutions;
    /// `None` (and a missing quantity) when nothing can stand in for it.
    fn target_format(&mut self, wanted: Format, blend: bool) -> Option<TargetFormat> {
        let w = TargetFormat::from_work(wanted);
        let used = priced_format(self.prof, wanted, blend);
        if used == Some(w) {
            return used;
        }
        let reason = match self.prof.caps(w) {
            None => "not listed by the profile",
            Some(c) if !c.render => "cannot be rendered",
            Some(_) => "cannot be blended",
        };
        if !self.subs.iter().any(|s| s.wanted == kebab(w)) {
            self.subs.push(Substitution {
                wanted: kebab(w),
                used: used.map(kebab),
                reason: format!("{} {reason}", kebab(w)),
                fill_ms: None,
            });
        }
        if used.is_none() {
            self.need(
                &format!("a renderable format for {}", kebab(w)),
                Quantity::Unknown,
            );
        }
        used
    }

    /// Fill rate of a format (its blend rate when blending).
    fn fill_rate(&mut self, f: TargetFormat, blend: bool) -> Option<f64> {
        let c = self.prof.caps(f)?;
        let (q, what) = if blend {
            (c.blend_gpix, format!("formats.{}.blend_gpix", kebab(f)))
        } else {
            (c.fill_gpix, format!("formats.{}.fill_gpix", kebab(f)))
        };
        self.need(&what, q)
    }

    /// Cost of one fetch in bilinear 32-bit fetches.
    fn texel_cost(&mut self, filter: Filter, format: Format) -> Option<f64> {
        let t = &self.prof.texture;
        let (point, tri, cmp, b64, b128) = (
            t.point_cost,
            t.trilinear_cost,
            t.depth_compare_cost,
            t.texel_64bpp_cost,
            t.texel_128bpp_cost,
        );
        let f = match filter {
            Filter::Point => self.need("texture.point_cost", point)?,
            Filter::Bilinear => 1.0,
            Filter::Trilinear => self.need("texture.trilinear_cost", tri)?,
            Filter::DepthCompare => self.need("texture.depth_compare_cost", cmp)?,
        };
        let b = match format.bytes_per_texel() {
            0..=4 => 1.0,
            5..=8 => self.need("texture.texel_64bpp_cost", b64)?,
            _ => self.need("texture.texel_128bpp_cost", b128)?,
        };
        Some(f * b)
    }

    /// Texture, ALU and texture-memory terms of `n` invocations of `s`, at
    /// the compute rates when `compute` (a profile without them prices the
    /// dispatch as a pixel shader: see [`Pricing::compute`]).
    fn shader_terms(&mut self, s: &ShaderWork, n: f64, compute: bool) {
        let tex = &self.prof.texture;
        let (frag_rate, comp_rate) = (tex.bilinear_gtexels, tex.compute_bilinear_gtexels);
        let rate = if s.fetches.is_empty() {
            None
        } else if compute {
            self.need("texture.compute_bilinear_gtexels", comp_rate)
        } else {
            self.need("texture.bilinear_gtexels", frag_rate)
        };
        let mut seen: Vec<&str> = Vec::new();
        for f in &s.fetches {
            if let (Some(r), Some(c)) = (rate, self.texel_cost(f.filter, f.format)) {
                let ms = n * f.count * c / (r * G) * MS;
                let shares: f64 = f.spread.iter().map(|s| s.share).sum();
                if f.coherent {
                    self.u.texture += ms;
                } else if shares > 0.0 {
                    for s in &f.spread {
                        let bins = &mut self.u.texture_incoherent_by_radius;
                        add_spread(bins, s.radius_px, ms * s.share / shares);
                    }
                } else {
                    self.u.texture_incoherent += ms;
                }
            }
            // Memory: each texture's footprint is read about once per
            // invocation (neighbouring taps hit the cache); incoherent taps
            // of a pixel shader read their 4 texels each, a dispatch's as
            // its coherent taps (module docs).
            let bpt = f64::from(f.format.bytes_per_texel());
            if !f.coherent && !compute {
                self.u.memory += n * f.count * 4.0 * bpt;
            } else if !seen.contains(&f.texture.as_str()) {
                seen.push(&f.texture);
                self.u.memory += n * bpt;
            }
        }
        self.u.memory += n * (s.storage_read_bytes + s.storage_write_bytes);
        // Instructions over the profile's issue rate (`Alu::ginstr`).
        match self.prof.alu.ginstr(compute) {
            Ok(rate) => self.u.alu = n * s.alu / (rate * G) * MS,
            Err(missing) => {
                self.need(missing, Quantity::Unknown);
            }
        }
    }

    /// Load-op clears of `texels` each: in eDRAM at its internal rate,
    /// elsewhere at the format's fill rate (and through memory), except a
    /// depth/stencil clear on a profile with fast depth clears (it sets
    /// per-tile state and writes no sample: `raster.fast_depth_clear`).
    fn clears(&mut self, formats: &[Format], texels: f64) {
        for &f in formats {
            let bytes = texels * f64::from(f.bytes_per_texel());
            match self.prof.edram.as_ref().map(|e| e.internal_gbps) {
                Some(q) => {
                    if let Some(r) = self.need("edram.internal_gbps", q) {
                        self.u.clear += bytes / (r * G) * MS;
                    }
                }
                None => {
                    let depth = TargetFormat::from_work(f).class() == FormatClass::Depth;
                    if depth && self.prof.raster.fast_depth_clear {
                        continue;
                    }
                    let t = self.target_format(f, false);
                    if let Some(r) = t.and_then(|t| self.fill_rate(t, false)) {
                        self.u.clear += texels / (r * G) * MS;
                    }
                    self.mem_bytes += bytes;
                }
            }
        }
    }

    /// The MSAA compression that applies to this pass: the profile's off
    /// eDRAM (eDRAM holds every sample at its internal rate), none at 1x.
    fn compression(&self, msaa: u32) -> MsaaCompression {
        if msaa > 1 && self.prof.edram.is_none() {
            self.prof.raster.msaa_compression
        } else {
            MsaaCompression::None
        }
    }

    fn raster(&mut self, p: &PassInput) {
        let Work::Raster {
            shader,
            color,
            depth_stencil,
            width,
            height,
            triangles,
            msaa,
            clears,
        } = &p.work
        else {
            return;
        };
        let n = p.fragments as f64;
        let msaa = (*msaa).max(1);
        let pixels = f64::from(*width) * f64::from(*height);
        self.clears(
            clears,
            msaa::cleared_texels(pixels, msaa, self.compression(msaa)),
        );
        if let Some(s) = shader {
            self.shader_terms(s, n, false);
        }
        if msaa > self.prof.raster.max_msaa {
            self.overruns.push(format!(
                "{msaa}x MSAA, the profile allows {}x",
                self.prof.raster.max_msaa
            ));
        }
        let max_mrt = self.prof.raster.max_color_targets as usize;
        let splits = color.len().div_ceil(max_mrt).max(1);
        if splits > 1 {
            self.overruns.push(format!(
                "writes {} colour targets, the profile allows {max_mrt}: split into {splits} passes",
                color.len()
            ));
        }
        let mut target_bytes = self.color_writes(color, p, msaa);
        if let Some(ds) = depth_stencil {
            if let Some(b) = self.depth_writes(ds, p, n, msaa, color.is_empty()) {
                target_bytes.push(b);
            }
        }
        self.resolves(p, msaa);
        self.rejection(p, shader.is_some() && !color.is_empty(), msaa);
        let st = self.edram_tiles(*width, *height, msaa, &target_bytes);
        let mut geo_factor = splits as f64;
        if st > 1 {
            if let Some(e) = self.prof.edram.as_ref() {
                let q = e.tiled_geometry_factor;
                if let Some(f) = self.need("edram.tiled_geometry_factor", q) {
                    geo_factor *= f;
                }
            }
        }
        if *triangles > 0 {
            let q = self.prof.raster.triangles_gtris;
            if let Some(r) = self.need("raster.triangles_gtris", q) {
                self.u.geometry = *triangles as f64 * geo_factor / (r * G) * MS;
            }
        }
    }

    /// Fill time of the colour writes (MRTs one after another; at MSAA the
    /// larger of pixel and sample time, or under compression the ROP time of
    /// `msaa::rop_seconds`); returns each target's bytes.
    fn color_writes(&mut self, color: &[ColorWrite], p: &PassInput, msaa: u32) -> Vec<u32> {
        let n = p.fragments as f64;
        let comp = self.compression(msaa);
        let cov = Coverage::of(n, p.samples_passed as f64, msaa);
        let mut target_bytes = Vec::new();
        for cw in color {
            let Some(f) = self.target_format(cw.format, cw.blend) else {
                continue;
            };
            target_bytes.push(f.bytes());
            let rate = self.fill_rate(f, cw.blend);
            let mut t = rate.map(|r| n / (r * G) * MS);
            if msaa > 1 {
                let q = self.prof.raster.msaa_gsamples;
                let s = self.need("raster.msaa_gsamples", q);
                let caps = self.prof.caps(TargetFormat::Rgba8Unorm);
                let rgba8 = caps.and_then(|c| c.fill_gpix.value());
                t = match (rate, s, comp) {
                    (Some(r), Some(s), MsaaCompression::None) => {
                        Some((n / r).max(n * f64::from(msaa) / s) / G * MS)
                    }
                    // The per-sample rate is the 32 bpp one: wider formats
                    // pass the ROPs at their fill rate's share of RGBA8's.
                    (Some(r), Some(s), c) => {
                        let s = s * r / rgba8.unwrap_or(r);
                        Some(msaa::rop_seconds(&cov, msaa, c, r * G, s * G) * MS)
                    }
                    _ => None,
                };
            }
            if let Some(t) = t {
                self.u.fill += t;
                let wanted = kebab(TargetFormat::from_work(cw.format));
                if let Some(s) = self.subs.iter_mut().find(|s| s.wanted == wanted) {
                    *s.fill_ms.get_or_insert(0.0) += t;
                }
            }
            if self.prof.edram.is_none() {
                let rw = if cw.blend { 2.0 } else { 1.0 };
                let stored = msaa::colour_samples(n, &cov, msaa, comp);
                self.mem_bytes += stored * f64::from(f.bytes()) * rw;
            }
        }
        target_bytes
    }

    /// A multisampled pass's resolves into its single-sample images (`--msaa`)
    /// off eDRAM: each reads the samples its pixels store (all `msaa` of them,
    /// or under compression one per whole pixel: `msaa::stored_samples_per_pixel`)
    /// and writes one texel per pixel through memory. On eDRAM the resolve is
    /// the copy out of eDRAM a later read forces (`transfers`), at the resolved
    /// size, as on Xenos.
    fn resolves(&mut self, p: &PassInput, msaa: u32) {
        if self.prof.edram.is_some() {
            return;
        }
        let share = Coverage::of(p.fragments as f64, p.samples_passed as f64, msaa).partial_share();
        let read = msaa::stored_samples_per_pixel(share, msaa, self.compression(msaa));
        for iu in p
            .images
            .iter()
            .filter(|i| i.kind == ImageUseKind::ResolveTarget)
        {
            let Some(f) = self.target_format(iu.format, false) else {
                continue;
            };
            let texels = f64::from(iu.width) * f64::from(iu.height);
            self.mem_bytes += texels * f64::from(f.bytes()) * (read + 1.0);
        }
    }

    /// Depth/stencil traffic (a depth-only pass is bound by its Z writes);
    /// returns the target's bytes.
    fn depth_writes(
        &mut self,
        ds: &DepthStencilUse,
        p: &PassInput,
        n: f64,
        msaa: u32,
        depth_only: bool,
    ) -> Option<u32> {
        let f = self.target_format(ds.format, false)?;
        let passed = p.samples_passed as f64;
        if self.prof.edram.is_none() {
            let rw = f64::from(u8::from(ds.depth_test || ds.stencil_test))
                + f64::from(u8::from(ds.depth_write || ds.stencil_write));
            let stored = msaa::depth_samples(n, passed, msaa, self.compression(msaa));
            self.mem_bytes += stored * f64::from(f.bytes()) * rw;
        }
        if depth_only {
            let q = self.prof.raster.z_only_gsamples;
            if let Some(z) = self.need("raster.z_only_gsamples", q) {
                self.u.fill += passed / (z * G) * MS;
            }
        }
        Some(f.bytes())
    }

    /// Covered pixels the early tests discard cost the Z-only rate; in a
    /// depth-tested pass that passes nothing, its triangle lies in front of
    /// every surface and hierarchical Z rejects whole tiles (priced apart).
    fn rejection(&mut self, p: &PassInput, shades: bool, msaa: u32) {
        let Some(r) = p.rasterized_pixels else {
            return;
        };
        let q = self.prof.raster.z_only_gsamples;
        let Some(z) = self.need("raster.z_only_gsamples", q) else {
            return;
        };
        let shaded = if shades {
            p.fragments as f64
        } else {
            p.samples_passed as f64
        };
        let t = (r as f64 - shaded).max(0.0) * f64::from(msaa) / (z * G) * MS;
        let depth_tested = matches!(
            &p.work,
            Work::Raster { depth_stencil: Some(ds), .. } if ds.depth_test && !ds.depth_write
        );
        if depth_tested && p.samples_passed == 0 {
            self.u.reject_hiz = t;
        } else {
            self.u.reject = t;
        }
    }

    /// eDRAM tiles of the pass's targets; returns its screen tiles (1 off eDRAM).
    fn edram_tiles(&mut self, w: u32, h: u32, msaa: u32, target_bytes: &[u32]) -> u32 {
        let Some(e) = self.prof.edram.as_ref() else {
            return 1;
        };
        let footprint: u32 = target_bytes
            .iter()
            .map(|&b| edram::surface_tiles(w, h, msaa, b, e))
            .sum();
        let st = match edram::screen_tiles(w, h, msaa, target_bytes, e) {
            Some(s) => s,
            None => {
                self.overruns
                    .push("one row of tiles does not fit in eDRAM".into());
                1
            }
        };
        self.edram = Some(EdramUse {
            footprint_tiles: footprint,
            screen_tiles: st,
            predicated_tiling: st > 1,
            ..Default::default()
        });
        st
    }

    /// A dispatch; on a profile without a compute path (no compute ALU rate)
    /// it is priced as the pixel shader a port would write: one fragment per
    /// invocation at the pixel-shader rates, storage writes through memory.
    fn compute(&mut self, shader: &ShaderWork, n: f64) {
        let has_compute = self.prof.alu.has_compute();
        if !has_compute {
            self.subs.push(Substitution {
                wanted: "compute".into(),
                used: Some("pixel shader".into()),
                reason: "the profile has no compute path: priced as a full-screen \
                         pixel-shader pass, one fragment per invocation"
                    .into(),
                fill_ms: None,
            });
        }
        self.shader_terms(shader, n, has_compute);
        if has_compute {
            self.u.dispatch = true;
            self.u.shared = self.shared_ms(shader.shared_bytes * n);
        }
    }

    /// Time of `bytes` of workgroup shared memory at the profile's rate
    /// (0 without a byte: a profile lacking the rate prices such dispatches).
    fn shared_ms(&mut self, bytes: f64) -> f64 {
        if bytes <= 0.0 {
            return 0.0;
        }
        let q = self.prof.alu.compute_shared_gbytes;
        self.need("alu.compute_shared_gbytes", q)
            .map_or(0.0, |r| bytes / (r * G) * MS)
    }

    fn copy(&mut self, p: &PassInput, texels: u64, bpt: u32, rects: u32) {
        let fmt = p
            .images
            .iter()
            .find(|i| i.kind == ImageUseKind::CopyDestination)
            .or_else(|| p.images.first())
            .map(|i| i.format)
            .unwrap_or_else(|| format_of_bpp(bpt));
        let n = texels as f64;
        let bytes = n * f64::from(bpt);
        self.u.copy_rects = f64::from(rects);
        let f = self.target_format(fmt, false);
        if let Some(r) = f.and_then(|f| self.fill_rate(f, false)) {
            // Copies go through the pixel pipeline (a draw on eDRAM
            // consoles, the copy path elsewhere): one texel per pixel.
            self.u.fill += n / (r * G) * MS;
        }
        let Some(e) = self.prof.edram.as_ref() else {
            self.mem_bytes += 2.0 * bytes;
            return;
        };
        // Read as a texture, drawn into eDRAM, resolved out.
        let (rate, resolve) = (self.prof.texture.bilinear_gtexels, e.resolve_gbps);
        if let (Some(r), Some(c)) = (
            self.need("texture.bilinear_gtexels", rate),
            self.texel_cost(Filter::Point, fmt),
        ) {
            self.u.texture += n * c / (r * G) * MS;
        }
        self.mem_bytes += bytes;
        let ms = self
            .need("edram.resolve_gbps", resolve)
            .map(|r| bytes / (r * G) * MS);
        self.u.resolve += ms.unwrap_or(0.0);
        let dst = p
            .images
            .iter()
            .find(|i| i.kind == ImageUseKind::CopyDestination)
            .map_or("copy", |i| i.image.as_str());
        self.edram = Some(EdramUse {
            footprint_tiles: 0,
            screen_tiles: 1,
            predicated_tiling: false,
            resolves: vec![Transfer {
                image: dst.to_string(),
                bytes: bytes as u64,
                ms,
                forced_by: p.name.clone(),
            }],
            restores: Vec::new(),
        });
    }

    /// A clear outside a render pass (a buffer or image fill): a transfer
    /// command, whose fixed cost is a dispatch's.
    fn clear_pass(&mut self, p: &PassInput, texels: u64, bpt: u32) {
        self.u.dispatch = true;
        let fmt = p
            .images
            .first()
            .map(|i| i.format)
            .unwrap_or_else(|| format_of_bpp(bpt));
        self.clears(&[fmt], texels as f64);
    }
}
