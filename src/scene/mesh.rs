//! CPU-side geometry and material data, laid out so the renderer can upload it as-is.

use super::wrinkle_maps::{decode, MASKS, ZONES_PER_MASK};
use anyhow::{bail, Result};

use super::morph::{posed, Morph};
use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};

pub use super::vertex::Vertex;

/// An indexed triangle list. Front faces are counter-clockwise seen from outside, which is
/// what back-face culling and the "inside/outside" tests of the skin passes rely on.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub vertices: Vec<Vertex>,
    pub indices: Vec<u32>,
}

/// Axis-aligned bounding box in the mesh's own units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    pub fn size(&self) -> Vec3 {
        self.max - self.min
    }

    /// Smallest box holding every point; `None` for no points, because a box around
    /// nothing has no honest value.
    pub fn from_points(points: impl IntoIterator<Item = Vec3>) -> Option<Aabb> {
        let mut it = points.into_iter();
        let first = it.next()?;
        let mut b = Aabb {
            min: first,
            max: first,
        };
        for p in it {
            b.min = b.min.min(p);
            b.max = b.max.max(p);
        }
        Some(b)
    }

    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// Box around the 8 transformed corners: conservative, which is what culling and
    /// shadow fitting need.
    pub fn transformed(&self, m: &Mat4) -> Aabb {
        let corners = (0..8).map(|i| {
            let c = Vec3::new(
                if i & 1 == 0 { self.min.x } else { self.max.x },
                if i & 2 == 0 { self.min.y } else { self.max.y },
                if i & 4 == 0 { self.min.z } else { self.max.z },
            );
            m.transform_point3(c)
        });
        Aabb::from_points(corners).unwrap_or(*self)
    }

    /// Radius of the sphere around `center()` that holds the box.
    pub fn bounding_radius(&self) -> f32 {
        self.size().length() * 0.5
    }

    /// True when the boxes share interior volume (touching faces do not count).
    pub fn overlaps(&self, other: &Aabb) -> bool {
        self.min.cmplt(other.max).all() && other.min.cmplt(self.max).all()
    }
}

/// Raw RGBA8 pixels, row 0 = top of the image as decoded, which is also where glTF puts
/// v = 0, so UVs sample it without flipping.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    pub width: u32,
    pub height: u32,
    pub rgba8: Vec<u8>,
}

impl Texture {
    /// Shrinks the texture to fit within `max_dim` on both sides, keeping its aspect
    /// ratio, and returns whether it had to. A device cannot create an image larger than
    /// its maxImageDimension2D; a smaller, blurrier skin texture is better than no frame.
    ///
    /// Box filter: each output texel averages the source texels of its footprint. The
    /// footprints tile the source exactly (integer boundaries `x * W / w`), so every
    /// source texel counts once. Bytes are averaged as stored (sRGB albedo averages a
    /// little dark; at the 2x-4x reductions this is for, it does not show).
    pub fn downscale_to_fit(&mut self, max_dim: u32) -> bool {
        let max_dim = max_dim.max(1) as u64;
        let (sw, sh) = (self.width as u64, self.height as u64);
        if sw <= max_dim && sh <= max_dim {
            return false;
        }
        let (dw, dh) = if sw >= sh {
            (max_dim, (sh * max_dim / sw).clamp(1, max_dim))
        } else {
            ((sw * max_dim / sh).clamp(1, max_dim), max_dim)
        };
        let mut out = Vec::with_capacity((dw * dh * 4) as usize);
        for y in 0..dh {
            let (y0, y1) = (y * sh / dh, ((y + 1) * sh / dh).max(y * sh / dh + 1));
            for x in 0..dw {
                let (x0, x1) = (x * sw / dw, ((x + 1) * sw / dw).max(x * sw / dw + 1));
                let mut sum = [0u64; 4];
                for sy in y0..y1 {
                    let row = (sy * sw * 4) as usize;
                    let texels = self
                        .rgba8
                        .get(row + (x0 * 4) as usize..row + (x1 * 4) as usize)
                        .unwrap_or(&[]);
                    for px in texels.chunks_exact(4) {
                        for c in 0..4 {
                            sum[c] += px[c] as u64;
                        }
                    }
                }
                let n = (x1 - x0) * (y1 - y0);
                out.extend(sum.map(|s| ((s + n / 2) / n) as u8));
            }
        }
        self.width = dw as u32;
        self.height = dh as u32;
        self.rgba8 = out;
        true
    }
}

/// Shading parameters of one object. `skin` selects the subsurface path; the rest of the
/// numbers follow d'Eon & Luebke's skin model (Beckmann roughness, Kelemen/Szirmay-Kalos
/// specular scale).
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub skin: bool,
    /// Linear RGB, multiplied with `base_color` when there is one.
    pub base_color_factor: [f32; 3],
    /// sRGB-encoded albedo: upload as an `_SRGB` format so sampling linearises it.
    pub base_color: Option<Texture>,
    /// Linear tangent-space normal map (upload as `_UNORM`).
    pub normal_map: Option<Texture>,
    /// Linear specular intensity in R, a factor of `specular_intensity`
    /// (upload as `_UNORM`).
    pub specular_map: Option<Texture>,
    /// Beckmann roughness m in R, linear (replaces `roughness` where given;
    /// Weyrich et al. 2006 measured it per region of the face).
    pub roughness_map: Option<Texture>,
    /// SSS strength in R, linear, a factor of `sss_strength` (thesis eq.
    /// 4.3-4.4: 0 where nothing scatters, a beard or hair).
    pub sss_map: Option<Texture>,
    /// Expression wrinkles (thesis ch. 8): a partial-derivative wrinkle map
    /// and two zone masks, shown by the expression weights (`None`: none).
    pub wrinkles: Option<WrinkleMaps>,
    /// Beckmann m; skin ~0.3.
    pub roughness: f32,
    /// rho_s; skin ~0.18.
    pub specular_intensity: f32,
    /// 0..1, written to the alpha of the diffuse target so the blur passes know how much
    /// of each pixel scatters.
    pub sss_strength: f32,
}

/// The wrinkle map and the two zone masks, each RGBA8 (linear, uploaded as
/// UNORM).
#[derive(Clone, Debug, PartialEq)]
pub struct WrinkleMaps {
    /// R, G: the wrinkles' partial-derivative normal (x, y), encoded.
    pub wrinkle: Texture,
    /// Zone coverage in [0, 1], four zones per texture.
    pub masks: [Texture; MASKS],
}

impl WrinkleMaps {
    /// Checks the maps are what the shaders sample: non-empty, each texture's
    /// bytes four per texel.
    pub fn check(&self) -> anyhow::Result<()> {
        for (what, t) in [
            ("wrinkle map", &self.wrinkle),
            ("wrinkle mask 0", &self.masks[0]),
            ("wrinkle mask 1", &self.masks[1]),
        ] {
            if t.width == 0 || t.height == 0 || t.rgba8.len() != 4 * (t.width * t.height) as usize {
                anyhow::bail!(
                    "{what}: {}x{} with {} bytes (4 a texel expected)",
                    t.width,
                    t.height,
                    t.rgba8.len()
                );
            }
        }
        Ok(())
    }

    /// The bytes the three textures hold (what the chapter's 96 KB counts).
    pub fn bytes(&self) -> usize {
        self.wrinkle.rgba8.len() + self.masks.iter().map(|m| m.rgba8.len()).sum::<usize>()
    }

    /// Zone `z`'s mask (0..8) at texel `(x, y)` of its mask texture, in [0, 1].
    pub fn mask_texel(&self, z: usize, x: u32, y: u32) -> f32 {
        let t = &self.masks[z / ZONES_PER_MASK];
        let i = 4 * (y * t.width + x) as usize + z % ZONES_PER_MASK;
        f32::from(t.rgba8[i]) / 255.0
    }

    /// The wrinkle map's decoded partial derivative at texel `(x, y)`.
    pub fn wrinkle_texel(&self, x: u32, y: u32) -> [f32; 2] {
        let t = &self.wrinkle;
        let i = 4 * (y * t.width + x) as usize;
        [decode(t.rgba8[i]), decode(t.rgba8[i + 1])]
    }
}

impl Material {
    /// The untextured skin defaults the project uses everywhere.
    pub fn skin(base_color_factor: [f32; 3]) -> Material {
        Material {
            skin: true,
            base_color_factor,
            base_color: None,
            normal_map: None,
            specular_map: None,
            roughness_map: None,
            sss_map: None,
            wrinkles: None,
            roughness: 0.3,
            specular_intensity: 0.18,
            sss_strength: 1.0,
        }
    }

    /// The smallest strength at which any of its texels scatters (the
    /// material's strength times its map's smallest non-zero texel; 0 when
    /// nothing scatters): the narrowest the profile gets on it (eq. 4.3-4.4
    /// scale its radius), what the ground truth's sampling must resolve.
    pub fn min_scattering_strength(&self) -> f32 {
        let least = self.sss_map.as_ref().map_or(Some(255), |m| {
            m.rgba8
                .chunks_exact(4)
                .map(|t| t[0])
                .filter(|&r| r > 0)
                .min()
        });
        least.map_or(0.0, |r| self.sss_strength * r as f32 / 255.0)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    /// Its vertices as drawn: the rest mesh posed by `morph`'s weights
    /// (`morph::posed`), what every CPU consumer reads.
    pub mesh: Mesh,
    pub material: Material,
    /// Its morph targets and weights (none: a still mesh). The renderer
    /// deforms `rest` on the GPU (`morph::apply`).
    pub morph: Morph,
}

impl Object {
    /// Gives the object its targets (its mesh now is their rest shape),
    /// checks them and poses it by their weights.
    pub fn set_morph(&mut self, mut morph: Morph) -> Result<()> {
        if !morph.deforms() {
            self.morph = Morph::default();
            return Ok(());
        }
        morph.check(self.mesh.vertices.len())?;
        morph.rest = self.mesh.vertices.clone();
        self.morph = morph;
        self.pose();
        Ok(())
    }

    /// Its mesh posed by its morph's weights (`morph::posed`); a still
    /// object stays as it is.
    pub fn pose(&mut self) {
        if self.morph.deforms() {
            self.mesh.vertices = posed(&self.morph.rest, &self.morph);
        }
    }
}

impl Mesh {
    /// Bounds of the vertex positions; an empty mesh gets a zero box at the origin so
    /// callers that only frame a camera never have to special-case it (`validate`
    /// rejects empty meshes where it matters).
    pub fn bounds(&self) -> Aabb {
        Aabb::from_points(self.vertices.iter().map(|v| Vec3::from(v.position))).unwrap_or(Aabb {
            min: Vec3::ZERO,
            max: Vec3::ZERO,
        })
    }

    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Per-vertex tangents from UV derivatives (Lengyel's method): each triangle's
    /// dP/du and dP/dv are accumulated per vertex (area weighted, because the unnormalised
    /// derivatives already scale with triangle size), then Gram-Schmidt against the
    /// normal. The handedness in w says whether dP/dv agrees with cross(n, t). Vertices
    /// whose UVs are degenerate get an arbitrary vector orthogonal to the normal, which
    /// is harmless because a normal map cannot vary across a zero-area UV patch.
    pub fn generate_tangents(&mut self) {
        let n = self.vertices.len();
        let mut tan = vec![Vec3::ZERO; n];
        let mut bit = vec![Vec3::ZERO; n];
        for tri in self.indices.chunks_exact(3) {
            let [a, b, c] = [tri[0] as usize, tri[1] as usize, tri[2] as usize];
            if a >= n || b >= n || c >= n {
                continue;
            }
            let (va, vb, vc) = (self.vertices[a], self.vertices[b], self.vertices[c]);
            let e1 = Vec3::from(vb.position) - Vec3::from(va.position);
            let e2 = Vec3::from(vc.position) - Vec3::from(va.position);
            let d1 = Vec2::from(vb.uv) - Vec2::from(va.uv);
            let d2 = Vec2::from(vc.uv) - Vec2::from(va.uv);
            let det = d1.x * d2.y - d2.x * d1.y;
            if !det.is_finite() || det.abs() < 1e-12 {
                continue;
            }
            // Scaling by |det| rather than dividing keeps tiny UV islands from dominating.
            let sign = det.signum();
            let t = (e1 * d2.y - e2 * d1.y) * sign;
            let bt = (e2 * d1.x - e1 * d2.x) * sign;
            if !t.is_finite() || !bt.is_finite() {
                continue;
            }
            for i in [a, b, c] {
                tan[i] += t;
                bit[i] += bt;
            }
        }
        for (i, v) in self.vertices.iter_mut().enumerate() {
            let nrm = Vec3::from(v.normal).normalize_or(Vec3::Y);
            let t = tan[i] - nrm * nrm.dot(tan[i]);
            let (t, w) = match t.try_normalize() {
                Some(t) => {
                    let w = if nrm.cross(t).dot(bit[i]) < 0.0 {
                        -1.0
                    } else {
                        1.0
                    };
                    (t, w)
                }
                None => (nrm.any_orthonormal_vector(), 1.0),
            };
            v.tangent = [t.x, t.y, t.z, w];
        }
    }

    /// Smooth normals from area-weighted face normals. Vertices at the same position are
    /// treated as one (UV seams duplicate vertices), so seams do not show as creases.
    pub fn compute_normals(&mut self) {
        use std::collections::HashMap;
        // Each vertex's position class (vertices at one position share a normal),
        // looked up once a vertex rather than three times a triangle: the face's
        // expressions recompute normals seven times in every process.
        let mut classes: HashMap<[u32; 3], usize> = HashMap::with_capacity(self.vertices.len());
        let class: Vec<usize> = self
            .vertices
            .iter()
            .map(|v| {
                let next = classes.len();
                *classes.entry(v.position.map(f32::to_bits)).or_insert(next)
            })
            .collect();
        let mut acc = vec![Vec3::ZERO; classes.len()];
        for tri in self.indices.chunks_exact(3) {
            let ids = [tri[0], tri[1], tri[2]].map(|i| i as usize);
            if ids.iter().any(|&i| i >= self.vertices.len()) {
                continue;
            }
            let p = ids.map(|i| Vec3::from(self.vertices[i].position));
            let fnrm = (p[1] - p[0]).cross(p[2] - p[0]);
            for i in ids {
                acc[class[i]] += fnrm;
            }
        }
        for (v, c) in self.vertices.iter_mut().zip(class) {
            v.normal = acc[c].try_normalize().unwrap_or(Vec3::Y).into();
        }
    }

    /// Flat normals, as glTF requires for a primitive without NORMAL: every triangle gets
    /// its own three vertices carrying its face normal (shared vertices would average
    /// across the edge and smooth what the file says is faceted). Degenerate triangles
    /// cover no pixels; they get +Y rather than a NaN.
    pub fn make_flat_normals(&mut self) {
        let mut vertices = Vec::with_capacity(self.indices.len());
        for tri in self.indices.chunks_exact(3) {
            let Some(v) = tri
                .iter()
                .map(|&i| self.vertices.get(i as usize).copied())
                .collect::<Option<Vec<Vertex>>>()
            else {
                continue;
            };
            let p = |k: usize| Vec3::from(v[k].position);
            let n = (p(1) - p(0)).cross(p(2) - p(0)).normalize_or(Vec3::Y);
            vertices.extend(v.into_iter().map(|mut v| {
                v.normal = n.into();
                v
            }));
        }
        self.indices = (0..vertices.len() as u32).collect();
        self.vertices = vertices;
    }

    /// Applies a model transform: positions by `m`, normals by its inverse transpose,
    /// tangents by its linear part. A mirroring transform (negative determinant) would
    /// turn outside-CCW into outside-CW, so the winding is flipped back, as glTF requires.
    pub fn transform(&mut self, m: &Mat4) {
        let lin = Mat3::from_mat4(*m);
        let normal_m = lin.inverse().transpose();
        let mirrored = lin.determinant() < 0.0;
        for v in &mut self.vertices {
            v.position = m.transform_point3(Vec3::from(v.position)).into();
            let n = (normal_m * Vec3::from(v.normal)).normalize_or(Vec3::Y);
            v.normal = n.into();
            let t = Vec4::from(v.tangent);
            let tt = (lin * t.truncate()).normalize_or(n.any_orthonormal_vector());
            let w = if mirrored { -t.w } else { t.w };
            v.tangent = [tt.x, tt.y, tt.z, w];
        }
        if mirrored {
            for tri in self.indices.chunks_exact_mut(3) {
                tri.swap(1, 2);
            }
        }
    }

    /// Appends another mesh, rebasing its indices.
    pub fn append(&mut self, other: &Mesh) {
        let base = self.vertices.len() as u32;
        self.vertices.extend_from_slice(&other.vertices);
        self.indices.extend(other.indices.iter().map(|i| i + base));
    }

    /// Rejects meshes the GPU would choke on or silently misdraw: empty, not a whole number
    /// of triangles, indices past the end, or non-finite positions/normals.
    pub fn validate(&self) -> Result<()> {
        if self.vertices.is_empty() || self.indices.is_empty() {
            bail!(
                "mesh is empty ({} vertices, {} indices)",
                self.vertices.len(),
                self.indices.len()
            );
        }
        // `% 3` rather than `is_multiple_of`: the crate's rust-version is 1.85.
        #[allow(clippy::manual_is_multiple_of)]
        if self.indices.len() % 3 != 0 {
            bail!(
                "mesh index count {} is not a multiple of 3 (triangle list)",
                self.indices.len()
            );
        }
        let n = self.vertices.len();
        if let Some((pos, &i)) = self
            .indices
            .iter()
            .enumerate()
            .find(|(_, &i)| i as usize >= n)
        {
            bail!("mesh index {i} at position {pos} is out of range ({n} vertices)");
        }
        if let Some(i) = self
            .vertices
            .iter()
            .position(|v| !Vec3::from(v.position).is_finite())
        {
            bail!("mesh vertex {i} has a non-finite position");
        }
        if let Some(i) = self
            .vertices
            .iter()
            .position(|v| !Vec3::from(v.normal).is_finite())
        {
            bail!("mesh vertex {i} has a non-finite normal");
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vtx(p: [f32; 3], uv: [f32; 2]) -> Vertex {
        Vertex {
            position: p,
            normal: [0.0, 0.0, 1.0],
            uv,
            tangent: [0.0; 4],
        }
    }

    fn quad() -> Mesh {
        Mesh {
            vertices: vec![
                vtx([0.0, 0.0, 0.0], [0.0, 1.0]),
                vtx([1.0, 0.0, 0.0], [1.0, 1.0]),
                vtx([1.0, 1.0, 0.0], [1.0, 0.0]),
                vtx([0.0, 1.0, 0.0], [0.0, 0.0]),
            ],
            indices: vec![0, 1, 2, 0, 2, 3],
        }
    }

    #[test]
    fn vertex_is_48_bytes() {
        assert_eq!(std::mem::size_of::<Vertex>(), 48);
    }

    #[test]
    fn tangents_follow_u_and_handedness_follows_v() {
        let mut m = quad();
        m.generate_tangents();
        for v in &m.vertices {
            let t = Vec4::from(v.tangent);
            assert!((t.truncate() - Vec3::X).length() < 1e-5, "{t:?}");
            // v grows downward (glTF convention): dP/dv = -Y, cross(n, t) = +Y -> w = -1.
            assert_eq!(t.w, -1.0);
        }
        let mut flipped = quad();
        for v in &mut flipped.vertices {
            v.uv[1] = 1.0 - v.uv[1];
        }
        flipped.generate_tangents();
        assert!(flipped.vertices.iter().all(|v| v.tangent[3] == 1.0));
    }

    #[test]
    fn degenerate_uvs_still_give_orthogonal_unit_tangents() {
        let mut m = quad();
        for v in &mut m.vertices {
            v.uv = [0.5, 0.5];
        }
        m.generate_tangents();
        for v in &m.vertices {
            let t = Vec4::from(v.tangent).truncate();
            assert!((t.length() - 1.0).abs() < 1e-5);
            assert!(t.dot(Vec3::from(v.normal)).abs() < 1e-5);
        }
    }

    #[test]
    fn validate_catches_each_defect() {
        assert!(quad().validate().is_ok());
        let mut m = quad();
        m.indices.push(0);
        assert!(format!("{:#}", m.validate().unwrap_err()).contains("multiple of 3"));
        let mut m = quad();
        m.indices[4] = 9;
        assert!(format!("{:#}", m.validate().unwrap_err()).contains("out of range"));
        let mut m = quad();
        m.vertices[1].position[0] = f32::NAN;
        assert!(format!("{:#}", m.validate().unwrap_err()).contains("non-finite position"));
        assert!(format!("{:#}", Mesh::default().validate().unwrap_err()).contains("empty"));
    }

    #[test]
    fn mirroring_transform_keeps_ccw_outside() {
        let mut m = quad();
        m.generate_tangents();
        m.transform(&Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)));
        let p = |i: u32| Vec3::from(m.vertices[i as usize].position);
        let face_n = (p(m.indices[1]) - p(m.indices[0])).cross(p(m.indices[2]) - p(m.indices[0]));
        assert!(face_n.dot(Vec3::from(m.vertices[0].normal)) > 0.0);
        assert_eq!(m.vertices[0].tangent[3], 1.0);
    }

    #[test]
    fn bounds_and_aabb_helpers() {
        let b = quad().bounds();
        assert_eq!(b.min, Vec3::ZERO);
        assert_eq!(b.max, Vec3::new(1.0, 1.0, 0.0));
        assert_eq!(b.center(), Vec3::new(0.5, 0.5, 0.0));
        let moved = b.transformed(&Mat4::from_translation(Vec3::X * 2.0));
        assert!(!b.overlaps(&moved));
        assert_eq!(Mesh::default().bounds().size(), Vec3::ZERO);
    }

    #[test]
    fn flat_normals_unweld_and_follow_each_face() {
        // Two triangles folded along the shared edge 0-2: one in z = 0, one in x = 1.
        let mut m = Mesh {
            vertices: vec![
                vtx([0.0, 0.0, 0.0], [0.0; 2]),
                vtx([1.0, 0.0, 0.0], [0.0; 2]),
                vtx([1.0, 1.0, 0.0], [0.0; 2]),
                vtx([1.0, 0.0, -1.0], [0.0; 2]),
            ],
            indices: vec![0, 1, 2, 1, 3, 2],
        };
        m.make_flat_normals();
        assert_eq!(m.vertices.len(), 6);
        assert_eq!(m.indices, vec![0, 1, 2, 3, 4, 5]);
        for v in &m.vertices[..3] {
            assert_eq!(v.normal, [0.0, 0.0, 1.0]);
        }
        for v in &m.vertices[3..] {
            assert_eq!(v.normal, [1.0, 0.0, 0.0]);
        }
        assert_eq!(m.vertices[4].position, [1.0, 0.0, -1.0]);
        // Degenerate triangles get a unit normal, not NaN.
        let mut d = Mesh {
            vertices: vec![vtx([1.0; 3], [0.0; 2]); 3],
            indices: vec![0, 1, 2],
        };
        d.make_flat_normals();
        assert!(d.vertices.iter().all(|v| v.normal == [0.0, 1.0, 0.0]));
        d.validate().unwrap();
    }

    fn texture(w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 4]) -> Texture {
        let mut rgba8 = Vec::new();
        for y in 0..h {
            for x in 0..w {
                rgba8.extend(f(x, y));
            }
        }
        Texture {
            width: w,
            height: h,
            rgba8,
        }
    }

    #[test]
    fn downscale_to_fit_box_filters_and_keeps_aspect() {
        let mut small = texture(4, 2, |_, _| [1, 2, 3, 4]);
        let before = small.clone();
        assert!(!small.downscale_to_fit(4));
        assert_eq!(small, before);

        // 2x2 checker blocks of 0 and 200 average to 100 in every output texel.
        let mut t = texture(8, 4, |x, y| {
            let v = if (x + y) % 2 == 0 { 0 } else { 200 };
            [v, v, v, 255]
        });
        assert!(t.downscale_to_fit(4));
        assert_eq!((t.width, t.height), (4, 2));
        assert_eq!(t.rgba8.len(), 4 * 2 * 4);
        assert!(t.rgba8.chunks_exact(4).all(|p| p == [100, 100, 100, 255]));

        // A left half black and right half white stays split in the middle.
        let mut t = texture(10, 20, |x, _| if x < 5 { [0; 4] } else { [255; 4] });
        assert!(t.downscale_to_fit(8));
        assert_eq!((t.width, t.height), (4, 8));
        for row in t.rgba8.chunks_exact(16) {
            assert_eq!(&row[..4], &[0; 4]);
            assert_eq!(&row[12..], &[255; 4]);
        }

        // Non-integer ratios: constant channels stay constant and the size fits.
        let mut t = texture(1000, 3, |x, y| [(x % 256) as u8, (y * 100) as u8, 7, 255]);
        assert!(t.downscale_to_fit(333));
        assert_eq!((t.width, t.height), (333, 1));
        assert!(t.rgba8.chunks_exact(4).all(|p| p[1] == 100 && p[2] == 7));

        // Extreme aspect ratios never reach zero texels; max 0 is taken as 1.
        let mut t = texture(4096, 1, |_, _| [9; 4]);
        assert!(t.downscale_to_fit(16));
        assert_eq!((t.width, t.height), (16, 1));
        let mut t = texture(3, 5, |_, _| [9; 4]);
        assert!(t.downscale_to_fit(0));
        assert_eq!((t.width, t.height, t.rgba8.clone()), (1, 1, vec![9; 4]));
    }

    #[test]
    fn compute_normals_points_along_face_normal() {
        let mut m = quad();
        for v in &mut m.vertices {
            v.normal = [1.0, 0.0, 0.0];
        }
        m.compute_normals();
        assert!(m.vertices.iter().all(|v| v.normal == [0.0, 0.0, 1.0]));
    }
}
