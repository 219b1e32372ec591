//! Morph targets (glTF's, and the procedural face's expressions): per-vertex
//! offsets of position, normal and tangent, blended by weights. Pure: the
//! GPU's deform pass (`deform.comp`) computes [`apply`] exactly, operation
//! for operation (each product and sum rounded alone: the shader's `precise`),
//! and every CPU consumer (framing, the planner, the ground truth's samples,
//! texture space's stretch) reads [`posed`], the same vertices with unit
//! normals and tangents.
//!
//! A target covers a range of the object's vertices (`first`, its own
//! length): an object merged from several primitives keeps each primitive's
//! targets without storing zeros for the others.

use anyhow::{bail, Result};
use glam::Vec3;

use super::skin::Skin;
use super::vertex::Vertex;

/// One target's offsets over `first..first + position.len()`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MorphTarget {
    /// Its name (glTF `extras.targetNames`, or the face's expression).
    pub name: Option<String>,
    pub first: usize,
    pub position: Vec<[f32; 3]>,
    /// Empty, or one per position.
    pub normal: Vec<[f32; 3]>,
    /// Empty, or one per position (xyz; the handedness does not morph).
    pub tangent: Vec<[f32; 3]>,
}

impl MorphTarget {
    pub fn len(&self) -> usize {
        self.position.len()
    }

    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }
}

/// An object's deformation: its targets and the weights they are posed
/// with, then its skin (glTF's order: targets in bind space, then joints).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Morph {
    /// The object's vertices with every weight 0 and no joint moved: its
    /// bind pose (empty for a still object).
    pub rest: Vec<Vertex>,
    pub targets: Vec<MorphTarget>,
    /// One per target: the file's defaults, then the command line's, then
    /// an animation's at the frame's time.
    pub weights: Vec<f32>,
    /// Its joints (`None`: placed by its targets alone).
    pub skin: Option<Skin>,
}

impl Morph {
    /// Every weight zero and no skin: the rest mesh, no work.
    pub fn at_rest(&self) -> bool {
        self.skin.is_none() && self.weights.iter().all(|&w| w == 0.0)
    }

    /// Whether it deforms its object at all (targets or a skin).
    pub fn deforms(&self) -> bool {
        !self.targets.is_empty() || self.skin.is_some()
    }

    /// Checks the shapes against an object of `vertices` vertices: every
    /// target within the object, its attributes of one length, finite.
    pub fn check(&self, vertices: usize) -> Result<()> {
        if let Some(skin) = &self.skin {
            skin.check(vertices)?;
        }
        if self.weights.len() != self.targets.len() {
            bail!(
                "{} morph weights for {} targets",
                self.weights.len(),
                self.targets.len()
            );
        }
        if let Some(w) = self.weights.iter().find(|w| !w.is_finite()) {
            bail!("morph weight {w} is not finite");
        }
        for (i, t) in self.targets.iter().enumerate() {
            let n = t.len();
            if t.first + n > vertices {
                bail!(
                    "morph target {i} covers vertices {}..{}, past the object's {vertices}",
                    t.first,
                    t.first + n
                );
            }
            for (what, len) in [("NORMAL", t.normal.len()), ("TANGENT", t.tangent.len())] {
                if len != 0 && len != n {
                    bail!("morph target {i}: {what} has {len} offsets but POSITION has {n}");
                }
            }
            let all = t.position.iter().chain(&t.normal).chain(&t.tangent);
            if let Some(k) = all.clone().position(|v| v.iter().any(|c| !c.is_finite())) {
                bail!("morph target {i}: offset {k} is not finite");
            }
        }
        Ok(())
    }

    /// Sets weights by the command line's `NAME=W` or `INDEX=W` entries.
    pub fn set_weights(&mut self, entries: &[(String, f32)]) -> Result<()> {
        for (key, w) in entries {
            if !w.is_finite() {
                bail!("morph weight {key}={w} is not finite");
            }
            let i = match key.parse::<usize>() {
                Ok(i) if i < self.targets.len() => i,
                Ok(i) => bail!(
                    "morph target {i} does not exist ({} targets)",
                    self.targets.len()
                ),
                Err(_) => self
                    .targets
                    .iter()
                    .position(|t| t.name.as_deref() == Some(key))
                    .ok_or_else(|| {
                        let names: Vec<&str> = self
                            .targets
                            .iter()
                            .filter_map(|t| t.name.as_deref())
                            .collect();
                        anyhow::anyhow!(
                            "no morph target is named '{key}' (named: {})",
                            if names.is_empty() {
                                "none".to_string()
                            } else {
                                names.join(", ")
                            }
                        )
                    })?,
            };
            self.weights[i] = *w;
        }
        Ok(())
    }
}

impl Morph {
    /// Moves the rest shape by `m` (a rigid motion whose rotation is `q`)
    /// and turns the offsets with it; a skinned rest stays in its bind
    /// space and its joints move instead.
    pub fn rotate(&mut self, m: &glam::Mat4, q: glam::Quat) {
        if let Some(skin) = &mut self.skin {
            skin.transform(m);
            return;
        }
        if self.targets.is_empty() {
            return;
        }
        for v in &mut self.rest {
            v.position = m.transform_point3(Vec3::from(v.position)).into();
            v.normal = (q * Vec3::from(v.normal)).into();
            let t = q * Vec3::from([v.tangent[0], v.tangent[1], v.tangent[2]]);
            v.tangent = [t.x, t.y, t.z, v.tangent[3]];
        }
        let turn = |v: &mut Vec<[f32; 3]>| {
            for d in v.iter_mut() {
                *d = (q * Vec3::from(*d)).into();
            }
        };
        for t in &mut self.targets {
            turn(&mut t.position);
            turn(&mut t.normal);
            turn(&mut t.tangent);
        }
    }
}

/// `a + w * d`, each operation rounded alone (what `precise` keeps the
/// shader to).
fn mad(a: [f32; 3], w: f32, d: [f32; 3]) -> [f32; 3] {
    [a[0] + w * d[0], a[1] + w * d[1], a[2] + w * d[2]]
}

/// The morphed vertices, exactly as the deform pass writes them: each target
/// in order adds weight x offset; normals and tangents are left unnormalised
/// (every vertex shader normalises them). Targets of weight 0 are skipped, as
/// the pass skips them (x + 0 * d is x for finite d anyway).
pub fn apply(rest: &[Vertex], morph: &Morph) -> Vec<Vertex> {
    let mut out = rest.to_vec();
    for (t, &w) in morph.targets.iter().zip(&morph.weights) {
        if w == 0.0 {
            continue;
        }
        for k in 0..t.len() {
            let v = &mut out[t.first + k];
            v.position = mad(v.position, w, t.position[k]);
            if let Some(d) = t.normal.get(k) {
                v.normal = mad(v.normal, w, *d);
            }
            if let Some(d) = t.tangent.get(k) {
                let [x, y, z] = mad([v.tangent[0], v.tangent[1], v.tangent[2]], w, *d);
                v.tangent = [x, y, z, v.tangent[3]];
            }
        }
    }
    out
}

/// The vertices exactly as the deform pass writes them: [`apply`], then the
/// skin's joints (`skin::apply`) where it has one.
pub fn deformed(rest: &[Vertex], morph: &Morph) -> Vec<Vertex> {
    let morphed = apply(rest, morph);
    match &morph.skin {
        Some(skin) => super::skin::apply(&morphed, skin),
        None => morphed,
    }
}

/// [`deformed`] with unit normals and tangents: what CPU consumers read.
pub fn posed(rest: &[Vertex], morph: &Morph) -> Vec<Vertex> {
    let mut out = deformed(rest, morph);
    for v in &mut out {
        let n = Vec3::from(v.normal).normalize_or(Vec3::Y);
        v.normal = n.into();
        let t = Vec3::from([v.tangent[0], v.tangent[1], v.tangent[2]]);
        let t = (t - n * n.dot(t)).normalize_or(n.any_orthonormal_vector());
        v.tangent = [t.x, t.y, t.z, v.tangent[3]];
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vertex(p: [f32; 3]) -> Vertex {
        Vertex {
            position: p,
            normal: [0.0, 0.0, 1.0],
            uv: [0.0; 2],
            tangent: [1.0, 0.0, 0.0, -1.0],
        }
    }

    #[test]
    fn weights_blend_offsets_within_each_targets_range() {
        let rest = vec![
            vertex([0.0; 3]),
            vertex([1.0, 0.0, 0.0]),
            vertex([2.0, 0.0, 0.0]),
        ];
        let m = Morph {
            targets: vec![
                MorphTarget {
                    name: Some("up".into()),
                    first: 1,
                    position: vec![[0.0, 1.0, 0.0], [0.0, 2.0, 0.0]],
                    normal: vec![[1.0, 0.0, 0.0], [0.0; 3]],
                    tangent: vec![],
                },
                MorphTarget {
                    name: Some("out".into()),
                    first: 0,
                    position: vec![[0.0, 0.0, 4.0]],
                    ..Default::default()
                },
            ],
            weights: vec![0.5, 0.25],
            skin: None,
            rest: Vec::new(),
        };
        m.check(3).unwrap();
        let out = apply(&rest, &m);
        assert_eq!(out[0].position, [0.0, 0.0, 1.0]);
        assert_eq!(out[1].position, [1.0, 0.5, 0.0]);
        assert_eq!(out[2].position, [2.0, 1.0, 0.0]);
        // Unnormalised in `apply`, unit in `posed`; the handedness is kept.
        assert_eq!(out[1].normal, [0.5, 0.0, 1.0]);
        let p = posed(&rest, &m);
        assert!((Vec3::from(p[1].normal).length() - 1.0).abs() < 1e-6);
        assert_eq!(p[1].tangent[3], -1.0);
        let mut at_rest = m.clone();
        at_rest.weights = vec![0.0, 0.0];
        assert!(at_rest.at_rest() && apply(&rest, &at_rest) == rest);
    }

    #[test]
    fn bad_shapes_and_names_are_one_line_errors() {
        let mut m = Morph {
            targets: vec![MorphTarget {
                name: Some("smile".into()),
                first: 2,
                position: vec![[0.0; 3]; 2],
                ..Default::default()
            }],
            weights: vec![0.0],
            skin: None,
            rest: Vec::new(),
        };
        assert!(m
            .check(3)
            .unwrap_err()
            .to_string()
            .contains("past the object's 3"));
        m.check(4).unwrap();
        m.targets[0].normal = vec![[0.0; 3]];
        assert!(m
            .check(4)
            .unwrap_err()
            .to_string()
            .contains("NORMAL has 1 offsets"));
        m.targets[0].normal.clear();
        m.targets[0].position[1][2] = f32::NAN;
        assert!(m.check(4).unwrap_err().to_string().contains("not finite"));
        m.set_weights(&[("smile".into(), 0.5)]).unwrap();
        assert_eq!(m.weights, [0.5]);
        m.set_weights(&[("0".into(), 1.0)]).unwrap();
        assert_eq!(m.weights, [1.0]);
        let e = m.set_weights(&[("frown".into(), 1.0)]).unwrap_err();
        assert!(e.to_string().contains("named: smile"), "{e}");
        assert!(m.set_weights(&[("3".into(), 1.0)]).is_err());
        assert!(m.set_weights(&[("0".into(), f32::INFINITY)]).is_err());
    }
}
