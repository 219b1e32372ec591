//! The numbers the shaders and the Rust code share, written once.
//!
//! tools/build.rs compiles this very file into itself (`#[path]`) and writes
//! [`glsl`]'s text to `shader_constants.glsl` on the shaders' include path, so
//! no shader spells these numbers again; the Rust modules that own their
//! meaning (`skin::profile`, `skin::ssg`, `reference::tissue`...) re-export
//! them. Because the build script compiles it alone, this file names no other
//! module and imports only std (tests/suite/layers.rs checks that).
//!
//! Floats are written as Rust prints them, the shortest text that reads back
//! as the same f32: glslang then stores the same bits as it did for the
//! hand-written literals these replace.

use std::fmt::Write as _;

/// Variances (mm^2) of the six-Gaussian skin fit, Table 4.2.
pub const SIX_GAUSSIAN_VARIANCES_MM2: [f32; 6] = [0.0064, 0.0484, 0.187, 0.567, 1.99, 7.41];

/// Weights `w_i` (rows: one Gaussian; columns: R, G, B) of the six-Gaussian
/// skin fit, Table 4.2. Each channel sums to 1 (unit total diffuse response).
pub const SIX_GAUSSIAN_WEIGHTS_RGB: [[f32; 3]; 6] = [
    [0.233, 0.455, 0.649],
    [0.1, 0.336, 0.344],
    [0.118, 0.198, 0.0],
    [0.113, 0.007, 0.007],
    [0.358, 0.004, 0.0],
    [0.078, 0.0, 0.0],
];

/// The six-Gaussian profile's Gaussians the ground truth sums over the
/// supersampled visible surface (the first ones); the rest it gathers from
/// surface samples (`reference::sampling` says why three).
pub const NARROW_GAUSSIANS: usize = 3;

/// The rest of the six: the Gaussians the ground truth gathers from samples.
pub const WIDE_GAUSSIANS: usize = SIX_GAUSSIAN_VARIANCES_MM2.len() - NARROW_GAUSSIANS;

/// Radius (mm) splitting Burley's profile in the ground truth: the
/// supersampled screen pass integrates `r < BURLEY_NEAR_MM`, the surface
/// samples `r >= BURLEY_NEAR_MM` (`reference::burley` says why 1 mm).
pub const BURLEY_NEAR_MM: f32 = 1.0;

/// Subsamples (per axis, each side of the pixel's point) whose weights the
/// ground truth's Burley screen pass integrates over the subsample's cell
/// (the 1/r singularity); farther ones take R(r) A (`reference::burley`).
pub const BURLEY_CELL_REACH: i32 = 2;

/// Parts per axis a near cell's integral is cut into (`reference::burley`).
pub const BURLEY_CELL_PARTS: usize = 4;

/// Burley's profile matched to the six Gaussians as `skin::kernel::burley_profile`
/// does (mean radius per channel, `A` = the channel's weight sum, at most 1):
/// its scaling factor `s = 2.5 / E[r]` (1/mm) and albedo per channel, in f64.
/// Written here from the table (this file names no other module); the
/// reference's tests hold it to `burley_profile()`.
pub fn burley_s_albedo() -> ([f64; 3], [f64; 3]) {
    let (mut total, mut mean) = ([0.0f64; 3], [0.0f64; 3]);
    for (&v, w) in SIX_GAUSSIAN_VARIANCES_MM2
        .iter()
        .zip(SIX_GAUSSIAN_WEIGHTS_RGB.iter())
    {
        let r = (std::f64::consts::PI * f64::from(v) / 2.0).sqrt();
        for c in 0..3 {
            total[c] += f64::from(w[c]);
            mean[c] += f64::from(w[c]) * r;
        }
    }
    let s = std::array::from_fn(|c| 2.5 / (mean[c] / total[c]));
    (s, total.map(|a| a.min(1.0)))
}

/// The 7 tap weights of Listing 4.1 (a Gaussian of one tap-step standard
/// deviation, taps at -3..=3 steps).
pub const LISTING_4_1_WEIGHTS: [f32; 7] = [0.006, 0.061, 0.242, 0.382, 0.242, 0.061, 0.006];

/// Distance (mm) under which two points are one in the tissue test: their
/// direction is rounding noise (a pixel's own subsample sits within f32
/// rounding of the pixel's point).
pub const SAME_POINT_MM: f32 = 1e-3;

/// Taps of the separable kernel's uniform array (separable_blur.frag's `samples`).
pub const SEPARABLE_MAX_SAMPLES: usize = 63;

/// UV islands texture-space diffusion's atlas uniform holds
/// (tsd_character.glsl, tsd_final.frag).
pub const TSD_MAX_ISLANDS: usize = 256;

/// Half width (texels) of the shadow's percentage-closer filter in
/// lighting.glsl: offsets -R..=R on each axis.
pub const PCF_RADIUS: u32 = 1;

/// Loop trips of that filter, per nested loop (the ALU estimate's input).
pub const PCF_TRIPS: [u32; 2] = [2 * PCF_RADIUS + 1; 2];

/// MLAA's distance searches (thesis ch. 9.4.1, Listing 9.3): bilinear
/// fetches per direction, two pixels each, so lines are followed 8 pixels
/// each way: the reach of the area texture (`aa::mlaa_area::MAX_DISTANCE`,
/// the Xbox 360's `tfetch2D` offsets; `post::mlaa` checks the two agree).
pub const MLAA_MAX_SEARCH_STEPS: u32 = 4;

/// Distances per subtexture of MLAA's area texture (Listing 9.4's
/// `NUM_DISTANCES`; `aa::mlaa_area::NUM_DISTANCES`, checked in `post::mlaa`).
pub const MLAA_NUM_DISTANCES: u32 = 9;

/// Levels of the bloom's pyramid (`post::bloom_pyramid` says why four):
/// half, quarter, eighth and sixteenth resolution, one texture binding each in
/// bloom_combine.frag.
pub const BLOOM_LEVELS: usize = 4;

/// Half width in texels of the bloom's Gaussian blur per level: taps
/// -R..=R, so 3 sigma of its one-texel Gaussian (`post::bloom_pyramid`).
pub const BLOOM_BLUR_RADIUS: u32 = 3;

/// Side of the square workgroup of the screen-space compute shaders
/// (reference_narrow.comp, reference_gather.comp, reference_resolve.comp: one
/// invocation a pixel): their `local_size_x` and `local_size_y`, and the
/// ground truth's dispatches of ceil(extent / side) groups. vk/shader.rs's
/// tests read every compute module's workgroup size back from its SPIR-V.
pub const COMPUTE_GROUP_SIDE: u32 = 8;

/// Side of the compute path's SSS tiles (tiles_classify.comp, separable_blur.comp):
/// one workgroup of SSS_TILE_SIDE^2 invocations per tile, HDRP's 16x16.
pub const SSS_TILE_SIDE: u32 = 16;

/// Invocations of the deform pass's one-dimensional workgroup (deform.comp:
/// one a vertex), the size its dispatches of ceil(vertices / size) divide by.
pub const DEFORM_GROUP_SIZE: u32 = 64;

/// Texels the compute blurs load on each side of a tile along their
/// direction (shared memory: the tile and its apron, 16 rows of 80 texels
/// (81 with the bank padding) of 12 bytes, 15.2 KiB, under the 16 KiB every
/// Vulkan device has). Wider kernels
/// read the texels beyond from the images (`method::tiles` says when).
pub const SSS_APRON_PX: u32 = 32;

/// Tile lists one classification writes (ssg's Gaussians after the first,
/// each skipped per tile by depth: at most the six-Gaussian fit's five).
pub const SSS_MAX_TILE_LISTS: usize = 6;

/// Intervals of the 2D gather's inverse-CDF table (`skin::gather`): its
/// `GATHER_LUT_SIZE + 1` radii travel four to a vec4 of a uniform block.
pub const GATHER_LUT_SIZE: usize = 256;
/// The vec4s that hold the gather's table.
pub const GATHER_LUT_VEC4S: usize = (GATHER_LUT_SIZE + 1).div_ceil(4);

/// A float as GLSL reads it back bit for bit (Rust's shortest round-trip
/// text always has a `.` or an exponent, so GLSL types it float).
fn float(v: f32) -> String {
    format!("{v:?}")
}

fn vec3(v: [f32; 3]) -> String {
    format!("vec3({}, {}, {})", float(v[0]), float(v[1]), float(v[2]))
}

/// `float[](a, b, ..)` / `vec3[](..)`: a GLSL array constructor.
fn array(kind: &str, items: impl IntoIterator<Item = String>) -> String {
    format!(
        "{kind}[]({})",
        items.into_iter().collect::<Vec<_>>().join(", ")
    )
}

/// The GLSL header: one `#define` per constant, under an include guard.
pub fn glsl() -> String {
    let mut s = String::from(
        "// Generated by tools/build.rs from src/shader_constants.rs: edit that file.\n\
         #ifndef DERMIS_SHADER_CONSTANTS_GLSL\n\
         #define DERMIS_SHADER_CONSTANTS_GLSL\n",
    );
    let mut def = |name: &str, value: String| {
        writeln!(s, "#define {name} {value}").expect("writing to a String");
    };
    let (v, w) = (SIX_GAUSSIAN_VARIANCES_MM2, SIX_GAUSSIAN_WEIGHTS_RGB);
    for i in 0..v.len() {
        def(&format!("SIX_GAUSSIAN_VARIANCE_{i}"), float(v[i]));
        def(&format!("SIX_GAUSSIAN_WEIGHT_{i}"), vec3(w[i]));
    }
    let n = NARROW_GAUSSIANS;
    def("NARROW_GAUSSIANS", n.to_string());
    def("WIDE_GAUSSIANS", WIDE_GAUSSIANS.to_string());
    def(
        "NARROW_VARIANCES_MM2",
        array("float", v[..n].iter().map(|&x| float(x))),
    );
    def(
        "NARROW_WEIGHTS",
        array("vec3", w[..n].iter().map(|&x| vec3(x))),
    );
    def(
        "NARROW_LAST_SIGMA_MM",
        float(SIX_GAUSSIAN_VARIANCES_MM2[n - 1].sqrt()),
    );
    def(
        "WIDE_VARIANCES_MM2",
        array("float", v[n..].iter().map(|&x| float(x))),
    );
    def(
        "WIDE_WEIGHTS",
        array("vec3", w[n..].iter().map(|&x| vec3(x))),
    );
    let (bs, ba) = burley_s_albedo();
    def("BURLEY_S_PER_MM", vec3(bs.map(|x| x as f32)));
    def("BURLEY_ALBEDO", vec3(ba.map(|x| x as f32)));
    def("BURLEY_NEAR_MM", float(BURLEY_NEAR_MM));
    def("BURLEY_CELL_REACH", BURLEY_CELL_REACH.to_string());
    def("BURLEY_CELL_PARTS", BURLEY_CELL_PARTS.to_string());
    for (i, &x) in LISTING_4_1_WEIGHTS.iter().enumerate() {
        def(&format!("LISTING_4_1_WEIGHT_{i}"), float(x));
    }
    def("SAME_POINT_MM", float(SAME_POINT_MM));
    def("SEPARABLE_MAX_SAMPLES", SEPARABLE_MAX_SAMPLES.to_string());
    def("TSD_MAX_ISLANDS", TSD_MAX_ISLANDS.to_string());
    def("PCF_RADIUS", PCF_RADIUS.to_string());
    def("PCF_TAPS", float((PCF_TRIPS[0] * PCF_TRIPS[1]) as f32));
    def("MLAA_MAX_SEARCH_STEPS", MLAA_MAX_SEARCH_STEPS.to_string());
    def("MLAA_NUM_DISTANCES", MLAA_NUM_DISTANCES.to_string());
    def("BLOOM_LEVELS", BLOOM_LEVELS.to_string());
    def("BLOOM_BLUR_RADIUS", BLOOM_BLUR_RADIUS.to_string());
    def("COMPUTE_GROUP_SIDE", COMPUTE_GROUP_SIDE.to_string());
    def("SSS_TILE_SIDE", SSS_TILE_SIDE.to_string());
    def("SSS_APRON_PX", SSS_APRON_PX.to_string());
    def("DEFORM_GROUP_SIZE", DEFORM_GROUP_SIZE.to_string());
    def("SSS_MAX_TILE_LISTS", SSS_MAX_TILE_LISTS.to_string());
    def("GATHER_LUT_VEC4S", GATHER_LUT_VEC4S.to_string());
    s.push_str("#endif\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_header_defines_every_constant_under_a_guard() {
        let h = glsl();
        assert!(h.starts_with("// Generated") && h.trim_end().ends_with("#endif"));
        for name in [
            "SIX_GAUSSIAN_VARIANCE_5",
            "SIX_GAUSSIAN_WEIGHT_5",
            "NARROW_VARIANCES_MM2",
            "WIDE_WEIGHTS",
            "NARROW_LAST_SIGMA_MM",
            "LISTING_4_1_WEIGHT_6",
            "SAME_POINT_MM",
            "SEPARABLE_MAX_SAMPLES",
            "TSD_MAX_ISLANDS",
            "PCF_TAPS",
            "COMPUTE_GROUP_SIDE",
            "SSS_TILE_SIDE",
            "SSS_APRON_PX",
            "DEFORM_GROUP_SIZE",
            "BURLEY_S_PER_MM",
            "BURLEY_ALBEDO",
            "BURLEY_NEAR_MM",
            "BURLEY_CELL_REACH",
        ] {
            assert!(h.contains(&format!("#define {name} ")), "{name}");
        }
        assert!(h.contains("#define NARROW_VARIANCES_MM2 float[](0.0064, 0.0484, 0.187)\n"));
        assert!(h.contains("#define PCF_TAPS 9.0\n"));
        assert_eq!(NARROW_GAUSSIANS + WIDE_GAUSSIANS, 6);
    }

    #[test]
    fn floats_read_back_as_the_same_bits() {
        for v in [
            0.0064f32,
            0.1,
            0.0,
            1e-3,
            7.41,
            0.432_434_98,
            1e-7,
            123456.0,
        ] {
            let t = float(v);
            assert!(
                t.contains('.') || t.contains('e'),
                "{t} would be an int in GLSL"
            );
            assert_eq!(t.parse::<f32>().unwrap().to_bits(), v.to_bits(), "{t}");
        }
    }

    /// No shader spells the profile or Listing 4.1 again: its numbers come
    /// from the generated header only.
    #[test]
    fn no_shader_writes_the_shared_numbers_itself() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
        let mut literals: Vec<String> = SIX_GAUSSIAN_VARIANCES_MM2
            .iter()
            .map(|&v| float(v))
            .collect();
        literals.extend(LISTING_4_1_WEIGHTS[3..].iter().map(|&v| float(v)));
        literals.push(float(SIX_GAUSSIAN_WEIGHTS_RGB[0][0]));
        let mut seen = 0;
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            let text = std::fs::read_to_string(&p).unwrap();
            for l in &literals {
                assert!(
                    !text.contains(l.as_str()),
                    "{} writes {l}: use shader_constants.glsl",
                    p.display()
                );
            }
            seen += 1;
        }
        assert!(seen > 30, "{seen}");
    }
}
