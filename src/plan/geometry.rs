//! The plan's geometry (issue 29, item 7): each character's level of detail
//! and whether it casts into the shadow map, chosen by the frame's own rule
//! (`scene::crowd_geometry`) and written into the plan file, with the
//! triangles each pass submits and the time the budget model charges for
//! them on the profile (its triangle rate, `raster.triangles_gtris`). What a
//! level changes is triangles only: the geometry pass shades about the same
//! pixels at every level, so the fill and shading of `dermis budget --plan`
//! stay with the frame. Pure: no device.

use glam::Mat4;

use crate::budget::profile::Profile;
use crate::render::RenderSettings;
use crate::scene::crowd_geometry::{self, CharacterGeometry, GeometryView};
use crate::scene::framing::Framing;
use crate::scene::lod;
use crate::scene::Scene;

/// One mesh a character draws: its level errors and triangles per level
/// (the full mesh first).
struct MeshLevels {
    errors: Vec<f32>,
    triangles: Vec<u64>,
}

impl MeshLevels {
    /// Its triangles in a character at `level` (`head`: the head's errors).
    fn triangles_at(&self, head: &[f32], level: u8) -> u64 {
        if self.errors.is_empty() {
            return self.triangles[0];
        }
        self.triangles[crowd_geometry::mesh_level(&self.errors, head, level) as usize]
    }
}

/// The planned geometry of a frame.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedGeometry {
    pub characters: Vec<CharacterGeometry>,
    /// Triangles each character submits to the geometry pass at its level.
    pub triangles: Vec<u64>,
    /// Triangles one character submits with its full meshes.
    pub full_triangles: u64,
    /// The geometry pass's and the shadow map's triangles, planned and with
    /// every character full and casting.
    pub geometry_pass: (u64, u64),
    pub shadow_pass: (u64, u64),
    /// The budget model's triangle time of both passes on the profile, ms,
    /// planned and full (`None`: the profile gives no triangle rate).
    pub triangle_ms: Option<(f64, f64)>,
}

impl PlannedGeometry {
    pub fn casters(&self) -> usize {
        self.characters.iter().filter(|c| c.casts_shadow).count()
    }

    /// One row per character: its level, triangles and whether it casts.
    pub fn table(&self) -> String {
        let mut s = format!(
            "{:>4} {:>5} {:>10} {:>6}  (geometry: level 0 = full meshes)\n",
            "char", "level", "triangles", "casts"
        );
        for (i, (c, t)) in self.characters.iter().zip(&self.triangles).enumerate() {
            s.push_str(&format!(
                "{i:>4} {:>5} {t:>10} {:>6}\n",
                c.level,
                if c.casts_shadow { "yes" } else { "no" }
            ));
        }
        s
    }

    /// The lines the plan prints and keeps among its notes.
    pub fn notes(&self, profile: &str, lod_pixels: f32) -> Vec<String> {
        let n = self.characters.len();
        let levels = if lod_pixels > 0.0 {
            format!("levels of detail at {lod_pixels} px of error")
        } else {
            "full meshes (--lod-pixels 0)".to_string()
        };
        let mut out = vec![
            format!(
                "geometry: {levels}: the geometry pass submits {} triangles ({:.1}% of {} full)",
                self.geometry_pass.0,
                100.0 * self.geometry_pass.0 as f64 / self.geometry_pass.1.max(1) as f64,
                self.geometry_pass.1
            ),
            format!(
                "shadow map: {} of {n} characters cast onto a receiver in view, {} triangles ({:.1}% of {} with every character full)",
                self.casters(),
                self.shadow_pass.0,
                100.0 * self.shadow_pass.0 as f64 / self.shadow_pass.1.max(1) as f64,
                self.shadow_pass.1
            ),
        ];
        out.push(match self.triangle_ms {
            Some((planned, full)) => format!(
                "triangle setup on {profile} (the budget model's rate, both passes, before eDRAM tiling): {planned:.4} ms, {full:.4} ms with every character full and casting; `dermis budget --plan` prices the whole frame"
            ),
            None => format!("triangle setup on {profile}: the profile gives no triangle rate"),
        });
        out
    }
}

/// Plans every character's geometry for the frame `framing` places, at
/// `settings`' levels (`--lod-pixels`; none at 0) and the frame's caster
/// rule, priced on `profile`.
pub fn plan_geometry(
    scene: &Scene,
    settings: &RenderSettings,
    framing: &Framing,
    models: &[Mat4],
    profile: &Profile,
) -> PlannedGeometry {
    let meshes: Vec<MeshLevels> = std::iter::once(&scene.head)
        .chain(&scene.parts)
        .map(|o| {
            if settings.lod_pixels > 0.0 {
                let l = lod::levels(&o.mesh);
                MeshLevels {
                    errors: l.iter().map(|l| l.error).collect(),
                    triangles: l.iter().map(|l| l.indices.len() as u64 / 3).collect(),
                }
            } else {
                MeshLevels {
                    errors: Vec::new(),
                    triangles: vec![o.mesh.triangle_count() as u64],
                }
            }
        })
        .collect();
    let errors: Vec<Vec<f32>> = meshes
        .iter()
        .filter(|m| !m.errors.is_empty())
        .map(|m| m.errors.clone())
        .collect();
    let characters = crowd_geometry::choose(
        scene,
        models,
        &GeometryView {
            camera: &framing.camera,
            width: settings.width,
            height: settings.height,
            light_view_proj: framing.light.view_proj,
            backdrop: framing.backdrop,
            shadow_size: settings.shadow_size,
            reach_units: crate::reference::sampling::cutoff_mm() / scene.mm_per_unit,
        },
        &errors,
        settings.lod_pixels,
    );
    let head = errors.first().cloned().unwrap_or_default();
    let at = |level: u8| {
        meshes
            .iter()
            .map(|m| m.triangles_at(&head, level))
            .sum::<u64>()
    };
    let full_triangles = at(0);
    let triangles: Vec<u64> = characters.iter().map(|c| at(c.level)).collect();
    let n = characters.len() as u64;
    let geometry_pass = (triangles.iter().sum(), full_triangles * n);
    let shadow_pass = (
        characters
            .iter()
            .zip(&triangles)
            .filter(|(c, _)| c.casts_shadow)
            .map(|(_, t)| t)
            .sum(),
        full_triangles * n,
    );
    let triangle_ms = profile.raster.triangles_gtris.value().map(|gtris| {
        let ms = |t: u64| t as f64 / (gtris * 1e9) * 1e3;
        (
            ms(geometry_pass.0 + shadow_pass.0),
            ms(geometry_pass.1 + shadow_pass.1),
        )
    });
    PlannedGeometry {
        characters,
        triangles,
        full_triangles,
        geometry_pass,
        shadow_pass,
        triangle_ms,
    }
}
