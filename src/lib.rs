//! dermis: a hand-written Vulkan (ash) renderer for real-time human skin that
//! measures what every pass costs on the GPU.
//!
//! The modules stand in the layers of [`LAYERS`], bottom up: a module uses only
//! those of its own layer or below (tests/suite/layers.rs checks it on every
//! path the code names, reading this list). The pure core, the first layer,
//! and the pure files above it (the layer test's `PURE_FILES`: metrics, the
//! cost model, the planner's math) name neither `ash`, `crate::vk` nor
//! `crate::graph`, nor reach them through any file they lead to. `main.rs`
//! calls the command wing (`app`), which parses the arguments and runs them.
pub mod aa;
pub mod accuracy;
pub mod app;
pub mod bench;
pub mod budget;
pub mod checks;
pub mod embedded;
pub mod eval;
pub mod files;
pub mod format;
pub mod graph;
pub mod header;
pub mod method;
pub mod mix;
pub mod output;
pub mod plan;
pub mod plot;
pub mod post;
pub mod ranges;
pub mod reference;
pub mod render;
pub mod report;
pub mod run;
pub mod scene;
pub mod shader_constants;
pub mod skin;
pub mod trace;
pub mod view;
pub mod vk;
pub mod work;

/// The module layers, bottom up: a module may use the modules of its own
/// layer or of a lower one, never a higher one (within a layer, no two form a
/// cycle). Written once, here: tests/suite/layers.rs checks the code against
/// it, and the docs point to it.
pub const LAYERS: &[&[&str]] = &[
    // The pure core, no Vulkan: the one door every user-supplied file is read
    // through (regular files only, sizes bounded); the format table; the
    // numbers shared with the shaders; the vocabulary of a pass's work; the
    // view's scale and the SSS region; meshes and framing; profiles, kernels
    // and the CPU mirrors of the passes; the ground truth's sampling and chunk
    // plan; the measured accuracy model; the MLAA and SMAA lookup tables and
    // edge references.
    // The run header of every JSON file, every number's range, the data built
    // into the binary, the one-time checks' counts.
    &[
        "checks",
        "embedded",
        "files",
        "format",
        "header",
        "ranges",
        "shader_constants",
        "work",
        "view",
        "scene",
        "skin",
        "reference",
        "accuracy",
        "aa",
    ],
    // Instance, physical and logical device, barrier table, memory, shaders
    // and their statistics, uploads, profiler.
    &["vk"],
    // Declared images, passes with their role, work and accesses; barriers
    // and usages derived, never written at call sites.
    &["graph"],
    // The SSS methods, one module each behind one trait, and their registry;
    // mix: which method each character gets (it reads the registry); post:
    // the anti-aliasing stages after the tone map (read by render).
    &["method", "mix", "post"],
    // The frame around a method.
    &["render"],
    // report.json's schema and statistics, floors, runs, the file writers,
    // the timeline, the console budget model, the chart writer.
    &[
        "report", "bench", "run", "output", "trace", "budget", "plot",
    ],
    // Metrics, bands, charts, the supersample filter, the sweeps' records.
    &["eval"],
    // A method per character under a budget, device-free (reads budget, mix,
    // render's settings); the checks' records and scoring.
    &["plan"],
    // The command wing: one file per subcommand, above everything it runs
    // (src/app/, issue 27).
    &["app"],
];
