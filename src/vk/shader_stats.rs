//! What a SPIR-V module does per invocation, read off its instructions: the
//! arithmetic instructions executed (function calls expanded, loop bodies times
//! their trip counts, both sides of a branch taken: an upper bound), how many of
//! them work on vectors, and its static image instructions. Pass declarations
//! take their ALU estimate from here, so the estimate follows the shader it
//! describes.
//!
//! Pure: parses the binary itself (SPIR-V 1.0, structured control flow as
//! glslang emits it: a loop's blocks lie between its header and its merge block).

use std::collections::HashMap;

use anyhow::{bail, Context as _, Result};

use super::shader::{spirv, words};

const OP_EXT_INST: u16 = 12;
const OP_TYPE_VECTOR: u16 = 23;
const OP_TYPE_MATRIX: u16 = 24;
/// OpUndef, OpConstantComposite, OpConstantNull, OpSpecConstantComposite:
/// module-scope values that may be vectors.
const MODULE_CONSTANTS: [u16; 4] = [1, 44, 46, 51];
const OP_FUNCTION: u16 = 54;
const OP_FUNCTION_END: u16 = 56;
const OP_FUNCTION_CALL: u16 = 57;
const OP_ENTRY_POINT: u16 = 15;
const OP_ATOMIC_IADD: u16 = 234;
const OP_LOOP_MERGE: u16 = 246;
const OP_LABEL: u16 = 248;

/// Whether `op` is an arithmetic instruction (conversions, arithmetic,
/// relational and logical, bit operations, extended instructions such as
/// GLSL.std.450's exp or clamp). Vector instructions count once each.
fn is_alu(op: u16) -> bool {
    matches!(op,
        OP_EXT_INST
        | 109..=124   // conversions (OpConvertFToU .. OpBitcast)
        | 126..=152   // OpSNegate .. OpSMulExtended (incl. Dot, matrix products)
        | 154..=191   // OpAny .. OpFUnordGreaterThanEqual (incl. OpSelect)
        | 194..=205) // shifts and bit operations
}

/// Whether `op` is a texture fetch: sampling, texel fetch or gather (not a
/// storage-image read: storage traffic is declared apart).
fn is_image_read(op: u16) -> bool {
    (87..=97).contains(&op)
}

struct Block {
    label: u32,
    alu: u32,
    /// Of `alu`, the instructions with a vector result or a vector operand.
    vector_alu: u32,
    /// Merge block of the loop this block heads, if it heads one.
    loop_merge: Option<u32>,
    calls: Vec<u32>,
}

struct Function {
    blocks: Vec<Block>,
}

/// Arithmetic instructions one invocation executes, and how many of them work
/// on vectors (a vector or matrix result, or a vector operand: `dot`, `length`,
/// `any`), the rest being scalar. A vec4 + scalar ALU (Xenos) issues one of the
/// first a clock and may pair a scalar one with it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AluSplit {
    pub total: f64,
    pub vector: f64,
}

impl AluSplit {
    pub fn scalar(&self) -> f64 {
        self.total - self.vector
    }
}

/// A parsed module: its functions and the entry point.
pub struct ShaderStats {
    functions: HashMap<u32, Function>,
    entry: u32,
    /// Static count of texture fetch instructions (every site once).
    pub image_reads: u32,
    /// Static count of OpAtomicIAdd (the fetch-counting build adds one per site).
    pub atomic_adds: u32,
}

impl ShaderStats {
    pub fn parse(code: &[u32]) -> Result<Self> {
        if code.len() < 5 || code[0] != 0x0723_0203 {
            bail!("not a SPIR-V module");
        }
        let mut functions = HashMap::new();
        let mut entry = None;
        let (mut image_reads, mut atomic_adds) = (0, 0);
        let mut current: Option<(u32, Function)> = None;
        // Ids of vector and matrix types, and the ids whose type is one of
        // them (results inside functions, and module-scope constants).
        let mut vector_types: Vec<u32> = Vec::new();
        let mut vector_ids: std::collections::HashSet<u32> = Default::default();
        let mut i = 5;
        while i < code.len() {
            let count = (code[i] >> 16) as usize;
            let op = (code[i] & 0xffff) as u16;
            if count == 0 || i + count > code.len() {
                bail!("malformed SPIR-V instruction at word {i}");
            }
            let args = &code[i + 1..i + count];
            if (op == OP_TYPE_VECTOR || op == OP_TYPE_MATRIX) && !args.is_empty() {
                vector_types.push(args[0]);
            }
            // Inside a function, an instruction whose first operand is a type
            // has a result: its id is the second (no other instruction there
            // takes a type id first: labels, pointers and values are not types).
            // Outside, only the constants (names and decorations also start
            // with a type's id, followed by no result).
            let has_result = current.is_some() || MODULE_CONSTANTS.contains(&op);
            if has_result && args.len() >= 2 && vector_types.contains(&args[0]) {
                vector_ids.insert(args[1]);
            }
            match op {
                OP_ENTRY_POINT if entry.is_none() => entry = Some(args[1]),
                OP_FUNCTION => current = Some((args[1], Function { blocks: Vec::new() })),
                OP_FUNCTION_END => {
                    if let Some((id, f)) = current.take() {
                        functions.insert(id, f);
                    }
                }
                OP_LABEL => {
                    if let Some((_, f)) = current.as_mut() {
                        f.blocks.push(Block {
                            label: args[0],
                            alu: 0,
                            vector_alu: 0,
                            loop_merge: None,
                            calls: Vec::new(),
                        });
                    }
                }
                _ => {
                    if is_image_read(op) {
                        image_reads += 1;
                    }
                    if op == OP_ATOMIC_IADD {
                        atomic_adds += 1;
                    }
                    if let Some(b) = current.as_mut().and_then(|(_, f)| f.blocks.last_mut()) {
                        match op {
                            OP_LOOP_MERGE => b.loop_merge = Some(args[0]),
                            OP_FUNCTION_CALL => b.calls.push(args[2]),
                            o if is_alu(o) => {
                                b.alu += 1;
                                // Operands after the result type and id (an
                                // extended instruction's after its set and
                                // number).
                                let first = if o == OP_EXT_INST { 4 } else { 2 };
                                let vector = vector_ids.contains(&args[1])
                                    || args
                                        .get(first..)
                                        .is_some_and(|a| a.iter().any(|x| vector_ids.contains(x)));
                                if vector {
                                    b.vector_alu += 1;
                                }
                            }
                            _ => {}
                        }
                    }
                }
            }
            i += count;
        }
        Ok(ShaderStats {
            functions,
            entry: entry.context("the module has no entry point")?,
            image_reads,
            atomic_adds,
        })
    }

    /// Arithmetic instructions one invocation executes, with the loops' trip
    /// counts given in the order their headers are reached (calls expanded
    /// where they are made). Every loop must get a trip count.
    pub fn alu(&self, trips: &[u32]) -> Result<f64> {
        Ok(self.alu_split(trips)?.total)
    }

    /// [`ShaderStats::alu`] with the instructions that work on vectors apart.
    pub fn alu_split(&self, trips: &[u32]) -> Result<AluSplit> {
        let mut next = 0usize;
        let total = self.eval(self.entry, trips, &mut next, 0)?;
        if next != trips.len() {
            bail!(
                "the shader has {next} loop(s) but {} trip count(s) were given",
                trips.len()
            );
        }
        Ok(total)
    }

    fn eval(&self, id: u32, trips: &[u32], next: &mut usize, depth: u32) -> Result<AluSplit> {
        if depth > 64 {
            bail!("call depth over 64 (recursion is not valid SPIR-V for shaders)");
        }
        let f = self
            .functions
            .get(&id)
            .with_context(|| format!("call of an unknown function %{id}"))?;
        // (merge label, multiplier) of the loops the traversal is inside.
        let mut loops: Vec<(u32, f64)> = Vec::new();
        let mut total = AluSplit::default();
        for b in &f.blocks {
            while loops.last().is_some_and(|(m, _)| *m == b.label) {
                loops.pop();
            }
            let outer = loops.last().map_or(1.0, |l| l.1);
            let mult = match b.loop_merge {
                Some(merge) => {
                    let t = *trips.get(*next).with_context(|| {
                        format!(
                            "loop {} has no trip count (only {} given)",
                            *next + 1,
                            trips.len()
                        )
                    })?;
                    *next += 1;
                    let m = outer * t as f64;
                    loops.push((merge, m));
                    m
                }
                None => outer,
            };
            total.total += mult * f64::from(b.alu);
            total.vector += mult * f64::from(b.vector_alu);
            for &c in &b.calls {
                let called = self.eval(c, trips, next, depth + 1)?;
                total.total += mult * called.total;
                total.vector += mult * called.vector;
            }
        }
        Ok(total)
    }
}

/// The statistics of the embedded shader `name`.
pub fn stats(name: &str) -> Result<ShaderStats> {
    ShaderStats::parse(&words(spirv(name)?)?).with_context(|| format!("shader {name}"))
}

/// The ALU estimate of the embedded shader `name` (see [`ShaderStats::alu`]).
/// Declarations call this at set-up; a mismatch between a shader's loops and
/// the trip counts its pass declares is a programmer error.
pub fn alu_estimate(name: &str, trips: &[u32]) -> f64 {
    stats(name)
        .and_then(|s| s.alu(trips))
        .unwrap_or_else(|e| panic!("ALU estimate of {name}: {e:#}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    // A loop's body scales with its trip count: the difference between two trip
    // counts is the body's size times their difference.
    #[test]
    fn loops_scale_with_their_trip_counts() {
        let s = stats("separable_blur.frag").unwrap();
        let a = s.alu(&[8]).unwrap();
        let b = s.alu(&[16]).unwrap();
        let body = (b - a) / 8.0;
        assert!(body >= 5.0, "loop body of {body} ALU instructions");
        assert!((s.alu(&[32]).unwrap() - (a + 24.0 * body)).abs() < 1e-9);
        assert!(s.alu(&[]).is_err());
        assert!(s.alu(&[8, 8]).is_err());
    }

    // Nested loops multiply: the geometry pass's 3x3 PCF.
    #[test]
    fn nested_loops_multiply() {
        let s = stats("geometry.frag").unwrap();
        let base = s.alu(&[3, 3]).unwrap();
        let wider = s.alu(&[3, 6]).unwrap();
        let wider2 = s.alu(&[6, 3]).unwrap();
        // Doubling the inner trips adds 3 x 3 inner bodies; doubling the outer
        // adds 3 x (outer body + 3 inner bodies): more.
        assert!(wider > base && wider2 > wider, "{base} {wider} {wider2}");
    }

    // Every fetch of every shader is counted in its fetch-counting build: one
    // atomic per fetch site, plus the invocation counter. A fetch written
    // without COUNTED(...) would escape the declared-work test; this catches it.
    #[test]
    fn every_fetch_site_is_counted_in_the_counting_build() {
        let mut checked = 0;
        for (name, _) in super::super::shader::SHADERS {
            let Some(base) = name.strip_suffix("#count") else {
                continue;
            };
            let normal = stats(base).unwrap();
            let counted = stats(name).unwrap();
            // The shader's own atomics (the compute path's tile list) stay.
            let own = normal.atomic_adds;
            assert!(
                own == 0 || base == "tiles_classify.comp",
                "{base}: {own} atomics"
            );
            let expected = own
                + if normal.image_reads > 0 {
                    normal.image_reads + 1
                } else {
                    0
                };
            assert_eq!(
                counted.atomic_adds, expected,
                "{base}: {} fetch sites, {} counters",
                normal.image_reads, counted.atomic_adds
            );
            assert_eq!(counted.image_reads, normal.image_reads, "{base}");
            checked += 1;
        }
        // Every fragment and compute shader has a counting build.
        let shaders = super::super::shader::SHADERS
            .iter()
            .filter(|(n, _)| !n.contains('#') && !n.ends_with(".vert"))
            .count();
        assert_eq!(checked, shaders);
    }

    /// One instruction: its word count and opcode, then its operands.
    fn inst(op: u16, args: &[u32]) -> Vec<u32> {
        let mut w = vec![((args.len() as u32 + 1) << 16) | u32::from(op)];
        w.extend_from_slice(args);
        w
    }

    // A hand-assembled module: a scalar add, a vec4 add, a dot product of two
    // vec4 (a scalar result from vector operands: the vector unit's dp4) and
    // a scalar multiply of the two scalars. Two of the four are vector work,
    // the dot product's operands a module-scope constant and a vec4 result.
    #[test]
    fn vector_instructions_are_told_from_scalar_ones() {
        let (void, fnty, float, v4, one, ones, main, label) = (1, 2, 3, 4, 5, 6, 7, 8);
        let (s, v, d, m) = (9, 10, 11, 12);
        let mut code = vec![0x0723_0203, 0x0001_0000, 0, 13, 0];
        for i in [
            inst(17, &[1]),                            // OpCapability Shader
            inst(14, &[0, 1]),                         // OpMemoryModel Logical GLSL450
            inst(15, &[4, main, 0x6e69_616d, 0]),      // OpEntryPoint Fragment %main "main"
            inst(19, &[void]),                         // OpTypeVoid
            inst(33, &[fnty, void]),                   // OpTypeFunction
            inst(22, &[float, 32]),                    // OpTypeFloat 32
            inst(23, &[v4, float, 4]),                 // OpTypeVector %float 4
            inst(43, &[float, one, 0x3f80_0000]),      // OpConstant 1.0
            inst(44, &[v4, ones, one, one, one, one]), // OpConstantComposite
            inst(54, &[void, main, 0, fnty]),          // OpFunction
            inst(248, &[label]),                       // OpLabel
            inst(129, &[float, s, one, one]),          // OpFAdd scalar
            inst(129, &[v4, v, ones, ones]),           // OpFAdd vec4
            inst(148, &[float, d, ones, v]),           // OpDot
            inst(133, &[float, m, s, d]),              // OpFMul scalar
            inst(253, &[]),                            // OpReturn
            inst(56, &[]),                             // OpFunctionEnd
        ] {
            code.extend(i);
        }
        let split = ShaderStats::parse(&code).unwrap().alu_split(&[]).unwrap();
        assert_eq!(
            split,
            AluSplit {
                total: 4.0,
                vector: 2.0
            }
        );
        assert_eq!(split.scalar(), 2.0);
    }

    // The split covers every instruction `alu` counts, loops included, and
    // both parts scale with the trips.
    #[test]
    fn the_split_adds_up_to_the_count() {
        let s = stats("separable_blur.frag").unwrap();
        let (a, b) = (s.alu_split(&[8]).unwrap(), s.alu_split(&[16]).unwrap());
        assert_eq!(a.total, s.alu(&[8]).unwrap());
        assert!(
            b.vector > a.vector && b.scalar() > a.scalar(),
            "{a:?} {b:?}"
        );
        let body = (b.vector - a.vector) / 8.0;
        assert_eq!(s.alu_split(&[24]).unwrap().vector, a.vector + 16.0 * body);
    }

    #[test]
    fn straight_shaders_need_no_trips_and_count_their_reads() {
        let s = stats("composite.frag").unwrap();
        assert!(s.alu(&[]).unwrap() >= 1.0);
        assert_eq!(s.image_reads, 2);
        assert_eq!(stats("tonemap.frag").unwrap().image_reads, 1);
        assert!(ShaderStats::parse(&[1, 2, 3]).is_err());
    }
}
