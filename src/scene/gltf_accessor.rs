//! Reads glTF accessors with bounded code of our own instead of the `gltf` crate's
//! readers, which panic on data the validator lets through (indices stored as BYTE, a
//! byteStride smaller than the element, an accessor running past its buffer view).
//!
//! Before any byte is read, each accessor is checked against what glTF allows for its
//! use (component type, normalized flag, type; core spec section 3.7.2.1, plus
//! KHR_mesh_quantization when the file uses it) and its layout against the data
//! (offset + stride * (count - 1) + element size within the buffer view, the view
//! within the buffer). Sparse accessors are supported. Every failure is one line
//! naming the accessor and what it was read for.

use super::gltf_source::Source;
use anyhow::{anyhow, bail, Result};
use gltf::accessor::{DataType, Dimensions};

/// Most elements one accessor may have. A sparse accessor without a buffer view is
/// zeros plus a few substitutions, so its count is not bounded by any data; this keeps
/// `count: 1e15` from allocating.
pub const MAX_ELEMENTS: usize = 1 << 27;

/// What an accessor is read for; decides which storage glTF allows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Use {
    Position,
    Normal,
    Tangent,
    TexCoord,
    Indices,
    /// A morph target's offsets (position, normal or tangent: VEC3).
    Offset,
    /// An animation sampler's keyframe times (SCALAR, FLOAT).
    KeyTimes,
    /// An animation sampler's values: translations and scales (VEC3),
    /// rotations (VEC4), morph weights (SCALAR).
    KeyVec3,
    KeyVec4,
    KeyScalar,
    /// A skin's joints per vertex (`JOINTS_n`: VEC4 of unsigned integers).
    Joints,
    /// Their weights (`WEIGHTS_n`: VEC4).
    Weights,
    /// A skin's inverse bind matrices (MAT4, FLOAT).
    InverseBind,
}

impl Use {
    fn dims(self) -> Dimensions {
        match self {
            Use::Position | Use::Normal | Use::Offset | Use::KeyVec3 => Dimensions::Vec3,
            Use::Tangent | Use::KeyVec4 | Use::Joints | Use::Weights => Dimensions::Vec4,
            Use::InverseBind => Dimensions::Mat4,
            Use::KeyTimes | Use::KeyScalar => Dimensions::Scalar,
            Use::TexCoord => Dimensions::Vec2,
            Use::Indices => Dimensions::Scalar,
        }
    }

    fn noun(self) -> &'static str {
        match self {
            Use::Position => "positions",
            Use::Normal => "normals",
            Use::Tangent => "tangents",
            Use::TexCoord => "texture coordinates",
            Use::Indices => "indices",
            Use::Offset => "morph offsets",
            Use::KeyTimes => "keyframe times",
            Use::KeyVec3 => "translations or scales",
            Use::KeyVec4 => "rotations",
            Use::KeyScalar => "morph weights",
            Use::Joints => "joints",
            Use::Weights => "joint weights",
            Use::InverseBind => "inverse bind matrices",
        }
    }

    /// Whether glTF allows this component type and normalized flag for this use.
    ///
    /// Core (3.7.2.1): positions, normals, tangents are FLOAT; texture coordinates are
    /// FLOAT or normalized UNSIGNED_BYTE/UNSIGNED_SHORT; indices are unnormalized
    /// UNSIGNED_BYTE/SHORT/INT. KHR_mesh_quantization adds (normalized or not)
    /// BYTE/UNSIGNED_BYTE/SHORT/UNSIGNED_SHORT positions and texture coordinates and
    /// normalized BYTE/SHORT normals and tangents. Normalized BYTE/SHORT texture
    /// coordinates are taken even without the extension: their meaning is the same
    /// either way and exporters write them.
    fn allows(self, ty: DataType, normalized: bool, quantization: bool) -> bool {
        use DataType::*;
        let small = matches!(ty, I8 | U8 | I16 | U16);
        let signed_small = matches!(ty, I8 | I16);
        match self {
            Use::Indices => matches!(ty, U8 | U16 | U32) && !normalized,
            // Core (3.7.3.3): joints are unsigned bytes or shorts; weights
            // floats or normalized unsigned bytes or shorts.
            Use::Joints => matches!(ty, U8 | U16) && !normalized,
            Use::Weights => (ty == F32 && !normalized) || (matches!(ty, U8 | U16) && normalized),
            _ if ty == F32 => !normalized,
            Use::Position => quantization && small,
            Use::Normal | Use::Tangent => quantization && signed_small && normalized,
            Use::TexCoord => small && (normalized || quantization),
            // KHR_mesh_quantization: BYTE or SHORT offsets, normalized or not.
            Use::Offset => quantization && signed_small,
            // Core (3.11): times and translations and scales are FLOAT;
            // rotations and weights may be normalized integers.
            Use::KeyTimes | Use::KeyVec3 | Use::InverseBind => false,
            Use::KeyVec4 | Use::KeyScalar => small && normalized,
        }
    }
}

pub fn type_name(ty: DataType) -> &'static str {
    match ty {
        DataType::I8 => "BYTE",
        DataType::U8 => "UNSIGNED_BYTE",
        DataType::I16 => "SHORT",
        DataType::U16 => "UNSIGNED_SHORT",
        DataType::U32 => "UNSIGNED_INT",
        DataType::F32 => "FLOAT",
    }
}

fn dims_name(d: Dimensions) -> &'static str {
    match d {
        Dimensions::Scalar => "SCALAR",
        Dimensions::Vec2 => "VEC2",
        Dimensions::Vec3 => "VEC3",
        Dimensions::Vec4 => "VEC4",
        Dimensions::Mat2 => "MAT2",
        Dimensions::Mat3 => "MAT3",
        Dimensions::Mat4 => "MAT4",
    }
}

/// One component as f32, with glTF's normalisation (3.11: signed values map to
/// max(c / MAX, -1)).
fn component_f32(b: &[u8], ty: DataType, normalized: bool) -> f32 {
    let b = |i: usize| b.get(i).copied().unwrap_or(0);
    match ty {
        DataType::F32 => f32::from_le_bytes([b(0), b(1), b(2), b(3)]),
        DataType::U32 => u32::from_le_bytes([b(0), b(1), b(2), b(3)]) as f32,
        DataType::I8 => {
            let v = b(0) as i8 as f32;
            if normalized {
                (v / 127.0).max(-1.0)
            } else {
                v
            }
        }
        DataType::U8 => {
            let v = b(0) as f32;
            if normalized {
                v / 255.0
            } else {
                v
            }
        }
        DataType::I16 => {
            let v = i16::from_le_bytes([b(0), b(1)]) as f32;
            if normalized {
                (v / 32767.0).max(-1.0)
            } else {
                v
            }
        }
        DataType::U16 => {
            let v = u16::from_le_bytes([b(0), b(1)]) as f32;
            if normalized {
                v / 65535.0
            } else {
                v
            }
        }
    }
}

/// One unsigned integer component (indices).
fn component_u32(b: &[u8], ty: DataType) -> u32 {
    let b = |i: usize| b.get(i).copied().unwrap_or(0);
    match ty {
        DataType::U8 | DataType::I8 => b(0) as u32,
        DataType::U16 | DataType::I16 => u16::from_le_bytes([b(0), b(1)]) as u32,
        _ => u32::from_le_bytes([b(0), b(1), b(2), b(3)]),
    }
}

/// The bytes of a buffer view, checked to lie within its buffer.
pub fn view_bytes<'s>(src: &'s Source, view: &gltf::buffer::View) -> Result<&'s [u8]> {
    let b = view.buffer().index();
    let buffer = src
        .buffers
        .get(b)
        .ok_or_else(|| anyhow!("bufferView {} refers to missing buffer {b}", view.index()))?;
    let (offset, len) = (view.offset(), view.length());
    offset
        .checked_add(len)
        .and_then(|end| buffer.get(offset..end))
        .ok_or_else(|| {
            anyhow!(
                "bufferView {} (offset {offset}, {len} bytes) runs past the end of buffer {b} ({} bytes)",
                view.index(),
                buffer.len()
            )
        })
}

/// Where `count` elements of `elem` bytes, `stride` apart from `offset`, lie in
/// `bytes`; `None` when they do not fit (or the arithmetic overflows).
fn span(offset: usize, stride: usize, elem: usize, count: usize, bytes: usize) -> Option<()> {
    let last = stride.checked_mul(count.checked_sub(1)?)?;
    let end = offset.checked_add(last)?.checked_add(elem)?;
    (end <= bytes).then_some(())
}

/// Reads every component of an accessor, decoded by `decode` (component bytes -> T),
/// after checking its storage is allowed for `usage` and its layout fits its data.
/// Returns `count * components` values.
fn read<T: Copy + Default>(
    src: &Source,
    acc: &gltf::Accessor,
    usage: Use,
    what: &str,
    decode: impl Fn(&[u8]) -> T,
) -> Result<Vec<T>> {
    let a = acc.index();
    let ty = acc.data_type();
    let normalized = acc.normalized();
    if acc.dimensions() != usage.dims() {
        bail!(
            "{what} accessor {a} has type {}, expected {}",
            dims_name(acc.dimensions()),
            dims_name(usage.dims())
        );
    }
    if normalized && matches!(ty, DataType::F32 | DataType::U32) {
        bail!(
            "{what} accessor {a} is {} with normalized set, which glTF forbids",
            type_name(ty)
        );
    }
    if !usage.allows(ty, normalized, src.quantization) {
        let norm = if normalized { "normalized " } else { "" };
        let hint = if src.quantization || usage == Use::Indices {
            ""
        } else {
            " (without KHR_mesh_quantization)"
        };
        bail!(
            "{what} accessor {a} is stored as {norm}{}, which glTF does not allow for {}{hint}",
            type_name(ty),
            usage.noun()
        );
    }
    let count = acc.count();
    if count == 0 {
        bail!("{what} accessor {a} has count 0");
    }
    if count > MAX_ELEMENTS {
        bail!(
            "{what} accessor {a} has {count} elements, more than the {MAX_ELEMENTS} dermis reads"
        );
    }
    let comps = acc.dimensions().multiplicity();
    let csize = ty.size();
    let elem = comps * csize;
    let element = |bytes: &[u8], at: usize, out: &mut Vec<T>| {
        for c in 0..comps {
            let at = at + c * csize;
            out.push(decode(bytes.get(at..at + csize).unwrap_or(&[])));
        }
    };
    let mut out = Vec::with_capacity(count * comps);
    match acc.view() {
        Some(view) => {
            let bytes = view_bytes(src, &view)?;
            let stride = view.stride().unwrap_or(elem);
            if stride < elem {
                bail!(
                    "{what} accessor {a}: byteStride {stride} of bufferView {} is smaller than an element ({elem} bytes)",
                    view.index()
                );
            }
            if usage == Use::Indices && view.stride().is_some() {
                bail!(
                    "{what} accessor {a}: bufferView {} has a byteStride, which glTF forbids for indices",
                    view.index()
                );
            }
            let offset = acc.offset();
            // glTF: an accessor's offset into its view and into its buffer MUST be a
            // multiple of its component size (a float read two bytes off is garbage,
            // not data; the fuzzer found coordinates of 5e36 that way).
            if (view.offset() + offset) % csize != 0 {
                bail!(
                    "{what} accessor {a}: its data starts at byte {} of buffer {}, not a multiple of its {csize}-byte components, which glTF forbids",
                    view.offset() + offset,
                    view.buffer().index()
                );
            }
            span(offset, stride, elem, count, bytes.len()).ok_or_else(|| {
                anyhow!(
                    "{what} accessor {a} ({count} x {elem} bytes, stride {stride}, offset {offset}) runs past the end of bufferView {} ({} bytes)",
                    view.index(),
                    bytes.len()
                )
            })?;
            for i in 0..count {
                element(bytes, offset + i * stride, &mut out);
            }
        }
        // Sparse without a view: zeros, then the substitutions.
        None => out.resize(count * comps, T::default()),
    }
    if let Some(sparse) = acc.sparse() {
        let n = sparse.count();
        if n == 0 || n > count {
            bail!("{what} accessor {a}: sparse count {n} is not within 1..={count}");
        }
        let idx = sparse.indices();
        let (iview, ioff) = (idx.view(), idx.offset());
        let ity = match idx.index_type() {
            gltf::accessor::sparse::IndexType::U8 => DataType::U8,
            gltf::accessor::sparse::IndexType::U16 => DataType::U16,
            gltf::accessor::sparse::IndexType::U32 => DataType::U32,
        };
        let ibytes = view_bytes(src, &iview)?;
        span(ioff, ity.size(), ity.size(), n, ibytes.len()).ok_or_else(|| {
            anyhow!(
                "{what} accessor {a}: sparse indices ({n} x {} bytes at offset {ioff}) run past the end of bufferView {}",
                ity.size(),
                iview.index()
            )
        })?;
        let vals = sparse.values();
        let (vview, voff) = (vals.view(), vals.offset());
        let vbytes = view_bytes(src, &vview)?;
        span(voff, elem, elem, n, vbytes.len()).ok_or_else(|| {
            anyhow!(
                "{what} accessor {a}: sparse values ({n} x {elem} bytes at offset {voff}) run past the end of bufferView {}",
                vview.index()
            )
        })?;
        let mut previous: Option<usize> = None;
        let mut values = Vec::with_capacity(comps);
        for k in 0..n {
            let at = ioff + k * ity.size();
            let target = component_u32(ibytes.get(at..).unwrap_or(&[]), ity) as usize;
            if target >= count || previous.is_some_and(|p| target <= p) {
                bail!(
                    "{what} accessor {a}: sparse index {target} (entry {k}) is out of order or not below the count {count}"
                );
            }
            previous = Some(target);
            values.clear();
            element(vbytes, voff + k * elem, &mut values);
            out[target * comps..(target + 1) * comps].copy_from_slice(&values);
        }
    }
    Ok(out)
}

/// Reads a float attribute of N components (positions, normals, tangents, texture
/// coordinates), normalised integers converted as glTF defines.
pub fn read_attribute<const N: usize>(
    src: &Source,
    acc: &gltf::Accessor,
    usage: Use,
    what: &str,
) -> Result<Vec<[f32; N]>> {
    let (ty, normalized) = (acc.data_type(), acc.normalized());
    let flat = read(src, acc, usage, what, |b| component_f32(b, ty, normalized))?;
    Ok(flat
        .chunks_exact(N)
        .map(|c| {
            let mut v = [0.0; N];
            v.copy_from_slice(c);
            v
        })
        .collect())
}

/// Reads a float accessor of any of `usage`'s components as one flat list
/// (normalised integers converted as glTF defines): animation samplers.
pub fn read_floats(src: &Source, acc: &gltf::Accessor, usage: Use, what: &str) -> Result<Vec<f32>> {
    let (ty, normalized) = (acc.data_type(), acc.normalized());
    read(src, acc, usage, what, |b| component_f32(b, ty, normalized))
}

/// Reads a skin's joints (`JOINTS_n`) as u32, four a vertex.
pub fn read_joints(src: &Source, acc: &gltf::Accessor, what: &str) -> Result<Vec<[u32; 4]>> {
    let ty = acc.data_type();
    let flat = read(src, acc, Use::Joints, what, |b| component_u32(b, ty))?;
    Ok(flat
        .chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect())
}

/// Reads an index accessor as u32.
pub fn read_indices(src: &Source, acc: &gltf::Accessor, what: &str) -> Result<Vec<u32>> {
    let ty = acc.data_type();
    read(src, acc, Use::Indices, what, |b| component_u32(b, ty))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn storage_rules_follow_the_spec() {
        use DataType::*;
        // Indices: unsigned, unnormalized; never BYTE or FLOAT.
        for ty in [U8, U16, U32] {
            assert!(Use::Indices.allows(ty, false, false));
            assert!(!Use::Indices.allows(ty, true, false));
        }
        assert!(!Use::Indices.allows(I8, false, true));
        assert!(!Use::Indices.allows(F32, false, true));
        // Texture coordinates: float or normalized small ints; plain BYTE only when
        // quantized.
        assert!(Use::TexCoord.allows(F32, false, false));
        for ty in [U8, U16, I8, I16] {
            assert!(Use::TexCoord.allows(ty, true, false));
            assert!(!Use::TexCoord.allows(ty, false, false));
            assert!(Use::TexCoord.allows(ty, false, true));
        }
        assert!(!Use::TexCoord.allows(U32, false, true));
        // Positions: float; small ints only when quantized.
        assert!(Use::Position.allows(F32, false, false));
        assert!(!Use::Position.allows(I16, false, false));
        assert!(Use::Position.allows(I16, false, true));
        assert!(Use::Position.allows(U8, true, true));
        // Normals: float; normalized signed when quantized.
        assert!(!Use::Normal.allows(I8, true, false));
        assert!(Use::Normal.allows(I8, true, true));
        assert!(!Use::Normal.allows(U8, true, true));
        assert!(!Use::Normal.allows(I16, false, true));
    }

    #[test]
    fn normalisation_matches_the_spec() {
        assert_eq!(component_f32(&[127], DataType::I8, true), 1.0);
        assert_eq!(component_f32(&[0x80], DataType::I8, true), -1.0);
        assert_eq!(component_f32(&[0x81], DataType::I8, true), -1.0);
        assert_eq!(component_f32(&[255], DataType::U8, true), 1.0);
        assert_eq!(component_f32(&[0xff, 0xff], DataType::U16, true), 1.0);
        assert_eq!(component_f32(&[0x00, 0x80], DataType::I16, true), -1.0);
        assert_eq!(component_f32(&[0xff, 0xff], DataType::I16, false), -1.0);
        assert_eq!(
            component_f32(&1.5f32.to_le_bytes(), DataType::F32, false),
            1.5
        );
        assert_eq!(component_u32(&[0x34, 0x12], DataType::U16), 0x1234);
        // Short input never panics.
        assert_eq!(component_f32(&[], DataType::F32, false), 0.0);
    }

    #[test]
    fn layout_span_is_checked_without_overflow() {
        assert!(span(0, 12, 12, 3, 36).is_some());
        assert!(span(0, 12, 12, 4, 36).is_none());
        assert!(span(4, 16, 12, 2, 32).is_some());
        assert!(span(4, 16, 12, 2, 31).is_none());
        assert!(span(0, 252, 12, usize::MAX, usize::MAX).is_none());
        assert!(span(usize::MAX, 4, 4, 1, usize::MAX).is_none());
        assert!(span(0, 4, 4, 0, 100).is_none());
    }
}
