//! eDRAM transfers over a whole frame (Xbox 360): a render target later
//! sampled, copied or read back is resolved once after its last write before
//! that read (charged to the writing pass: bytes = pixels x bytes per pixel at
//! `edram.resolve_gbps`); a pass that loads a target (blends into it, tests
//! against its depth) must find it in eDRAM, which holds only the previous draw
//! pass's targets, and only when neither pass was tiled; otherwise the target
//! is restored from main memory (charged to the loading pass, at memory
//! bandwidth, after a resolve of its contents if they were not resolved yet).
//! A pass drawn only in the SSS region's rectangles resolves and restores only
//! them (Xenos resolves take a source rectangle): its transfers move the
//! region's share of the target. Bytes are those of the format the profile
//! renders the target in (`units::priced_format`).

use std::collections::HashMap;

use crate::budget::edram;
use crate::budget::input::{FrameInput, PassInput};
use crate::budget::profile::{Profile, TargetFormat};
use crate::budget::units::{pass_units, priced_format, PassUnits, Transfer};
use crate::work::{ImageUse, ImageUseKind, Work};

const G: f64 = 1e9;
const MS: f64 = 1e3;

fn writes(kind: ImageUseKind) -> bool {
    matches!(
        kind,
        ImageUseKind::ColorTarget
            | ImageUseKind::ColorTargetLoad
            | ImageUseKind::DepthTarget
            | ImageUseKind::ResolveTarget
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

fn is_draw(p: &PassInput) -> bool {
    matches!(p.work, Work::Raster { .. })
}

/// The share of its render area a pass draws (region-limited passes: the
/// region's pixels; others all of it).
fn drawn_share(p: &PassInput) -> f64 {
    match (&p.work, p.rasterized_pixels) {
        (Work::Raster { width, height, .. }, Some(px)) => {
            (px as f64 / (f64::from(*width) * f64::from(*height)).max(1.0)).min(1.0)
        }
        _ => 1.0,
    }
}

/// Unit times of every pass of a frame on a profile, with eDRAM resolves and
/// restores (module docs).
pub fn price_units(prof: &Profile, frame: &FrameInput) -> Vec<PassUnits> {
    let mut out: Vec<PassUnits> = frame.passes.iter().map(|p| pass_units(prof, p)).collect();
    if prof.edram.is_none() {
        return out;
    }
    let mut t = Tracker {
        prof,
        shares: frame.passes.iter().map(drawn_share).collect(),
        resolve_rate: prof.edram.as_ref().and_then(|e| e.resolve_gbps.value()),
        mem_rate: prof.memory.bandwidth_gbps.value(),
        last_write: HashMap::new(),
    };
    // Which passes need several screen tiles (set by `pass_units`, fixed here).
    let tiled: Vec<bool> = out
        .iter()
        .map(|u| u.edram.as_ref().is_some_and(|x| x.screen_tiles > 1))
        .collect();
    let mut prev_draw: Option<usize> = None;
    for (j, p) in frame.passes.iter().enumerate() {
        for iu in p.images.iter().filter(|iu| reads_as_texture(iu.kind)) {
            t.resolve(iu, j, &p.name, &mut out);
        }
        if is_draw(p) {
            for iu in p.images.iter().filter(|iu| loads(iu.kind)) {
                let resident = prev_draw.is_some_and(|k| {
                    !tiled[k]
                        && !tiled[j]
                        && frame.passes[k]
                            .images
                            .iter()
                            .any(|x| x.image == iu.image && (writes(x.kind) || loads(x.kind)))
                });
                if !resident {
                    // Its contents must reach main memory first, then come back.
                    t.resolve(iu, j, &p.name, &mut out);
                    t.restore(iu, j, &p.name, &mut out);
                }
            }
            prev_draw = Some(j);
            for iu in p.images.iter().filter(|iu| writes(iu.kind)) {
                t.last_write.insert(iu.image.clone(), (j, false));
            }
        } else {
            // A copy or clear draws through eDRAM too: nothing stays resident.
            prev_draw = None;
        }
    }
    out
}

/// Per image, the pass that last wrote it into eDRAM and whether that write
/// has been resolved since.
struct Tracker<'a> {
    prof: &'a Profile,
    /// Per pass, the share of its area it draws.
    shares: Vec<f64>,
    resolve_rate: Option<f64>,
    mem_rate: Option<f64>,
    last_write: HashMap<String, (usize, bool)>,
}

impl Tracker<'_> {
    /// Bytes of `iu` as the profile stores it, times `share`.
    fn bytes(&self, iu: &ImageUse, share: f64) -> u64 {
        let f = priced_format(self.prof, iu.format, false)
            .unwrap_or_else(|| TargetFormat::from_work(iu.format));
        (edram::resolve_bytes(iu.width, iu.height, f.bytes()) as f64 * share).round() as u64
    }

    /// A read of `iu` by pass `j` forces the resolve of its last eDRAM write.
    fn resolve(&mut self, iu: &ImageUse, j: usize, by: &str, out: &mut [PassUnits]) {
        let Some((i, resolved)) = self.last_write.get_mut(&iu.image) else {
            return;
        };
        if *resolved || *i == j {
            return;
        }
        *resolved = true;
        let writer = *i;
        let bytes = self.bytes(iu, self.shares[writer]);
        let ms = self.resolve_rate.map(|r| bytes as f64 / (r * G) * MS);
        let pu = &mut out[writer];
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
                image: iu.image.clone(),
                bytes,
                ms,
                forced_by: by.to_string(),
            });
        }
    }

    /// Pass `j` loads `iu` from main memory back into eDRAM.
    fn restore(&self, iu: &ImageUse, j: usize, by: &str, out: &mut [PassUnits]) {
        let bytes = self.bytes(iu, self.shares[j]);
        let ms = self.mem_rate.map(|r| bytes as f64 / (r * G) * MS);
        let pu = &mut out[j];
        if let Some(ms) = ms {
            pu.units.restore += ms;
        }
        if let Some(eu) = pu.edram.as_mut() {
            eu.restores.push(Transfer {
                image: iu.image.clone(),
                bytes,
                ms,
                forced_by: by.to_string(),
            });
        }
    }
}
