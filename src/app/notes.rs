//! The options a command was given and does not read, each named in a note
//! with the reason (issue 27): a command line never silently means less than
//! it says. Their values are still checked (a NaN is an error even where it
//! would be unused). One table per command, below.

use super::cli::{flag, Command};
use super::request::Given;
use crate::method::{all_options, foreign_options};
use crate::render::RenderSettings;

/// Frame options the methods do not own, by clap id.
const METHOD_CHOICE: [&str; 3] = ["method", "assign", "plan"];
/// The options of the post chain.
const POST: [&str; 5] = ["aa", "bloom", "aa_edges", "smaa_preset", "msaa"];
/// What a frame's look takes that a plan does not read.
const LOOK: [&str; 5] = [
    "light_intensity",
    "ambient",
    "exposure",
    "no_transmittance",
    "transmittance_profile",
];

/// The notes for `command` given `given`: one per option it does not read.
pub fn ignored(command: &Command, given: &Given) -> Vec<String> {
    let mut notes = Vec::new();
    let mut note = |ids: &[&str], why: &str| {
        for id in ids {
            if given.has(id) {
                notes.push(format!("{} is ignored: {why}", flag(id)));
            }
        }
    };
    if given.has("shot") && given.has("distance") {
        note(&["shot"], "--distance gives the camera distance");
    }
    let method_options: Vec<&str> = all_options().iter().map(|(_, o)| o.key).collect();
    match command {
        Command::Render(_) | Command::Bench(_) => {
            if let Some(a) = ["assign", "plan"].into_iter().find(|a| given.has(a)) {
                let why = format!("{} gives each character its method", flag(a));
                note(&["method"], &why);
                note(&method_options, &why);
            }
        }
        Command::Budget(b) => {
            if b.compare_methods {
                note(&METHOD_CHOICE, "--compare-methods prices every method");
            } else if let Some(a) = ["assign", "plan"].into_iter().find(|a| given.has(a)) {
                let why = format!("{} gives each character its method", flag(a));
                note(&["method"], &why);
                note(&method_options, &why);
            }
        }
        Command::Reference(_) => note(&METHOD_CHOICE, "reference renders the ground truth"),
        Command::Eval(e) => {
            note(&METHOD_CHOICE, "eval sweeps every registered method");
            note(
                &["light_azimuth", "light_elevation"],
                "each view of eval's scene sets has its own key light",
            );
            note(
                &["skin_tone"],
                "eval's views keep their scenes' own skin colours",
            );
            if e.compare_texturing {
                note(&["texturing"], "--compare-texturing sweeps both texturings");
            }
            if e.scenes != "quick" {
                note(
                    &["distance", "shot"],
                    "each view of eval's scene sets has its own distance (--scenes quick takes one)",
                );
            } else {
                note(
                    &[
                        "scene",
                        "albedo",
                        "normal_map",
                        "spec_map",
                        "roughness_map",
                        "sss_map",
                        "sidecar_top_down",
                        "mm_per_unit",
                    ],
                    "--scenes quick renders the embedded procedural face",
                );
            }
            if e.scenes.starts_with("accuracy") {
                note(
                    &["fovy"],
                    "the accuracy set narrows the field of view to its crop of a 720-row frame",
                );
            }
        }
        Command::AaEval(a) => {
            note(&["aa"], "aa-eval runs every mode");
            note(
                &["msaa"],
                "aa-eval scores every MSAA count the device renders",
            );
            note(
                &["assign", "plan"],
                "aa-eval renders each view with --method",
            );
            note(
                &["distance", "shot"],
                "each view of aa-eval has its own distance",
            );
            let builtin = a
                .frame
                .scene
                .as_deref()
                .and_then(|p| p.to_str())
                .is_some_and(|s| s.starts_with(crate::scene::source::BUILTIN_PREFIX));
            if builtin {
                note(
                    &["scene"],
                    "aa-eval's views are built in (a glTF --scene adds its scan)",
                );
            }
        }
        Command::Plan(_) => {
            note(&["device", "validate"], "plan opens no device");
            note(&METHOD_CHOICE, "plan chooses each character's method");
            note(
                &method_options,
                "plan chooses each character's method and its settings",
            );
            note(&POST, "plan prices the skin SSS alone");
            note(
                &LOOK,
                "plan prices the skin SSS from the frame's geometry, not its light",
            );
        }
        Command::PlanCheck(_) => {
            note(
                &METHOD_CHOICE,
                "plan-check renders plans and uniform assignments",
            );
            note(
                &["heads", "layout", "distance", "shot", "crowd_walked"],
                "each scene of plan-check places its own characters",
            );
        }
        Command::PlanMotion(_) => {
            note(&METHOD_CHOICE, "plan-motion renders each frame's plan");
            note(
                &["crowd_walked"],
                "plan-motion walks the crowd by --walk-heads",
            );
        }
        Command::Compare(_) | Command::Kernel(_) | Command::Devices(_) | Command::Methods(_) => {}
    }
    notes
}

/// Method options given that the frame's one method does not read.
pub fn foreign(s: &RenderSettings) -> Vec<String> {
    // With --assign/--plan no --method is read (`ignored` says so).
    if s.assignment.is_some() {
        return Vec::new();
    }
    foreign_options(s.method, &s.options)
        .into_iter()
        .map(|f| format!("{f} does not apply to --method {}", s.method.name))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::cli::Cli;
    use clap::{CommandFactory, FromArgMatches};

    fn notes(args: &[&str]) -> Vec<String> {
        let m = Cli::command().try_get_matches_from(args).unwrap();
        let (_, sub) = m.subcommand().unwrap();
        let given = Given::of(sub);
        let cli = Cli::from_arg_matches(&m).unwrap();
        ignored(&cli.command, &given)
    }

    #[test]
    fn every_ignored_option_is_named_with_its_reason() {
        let n = notes(&[
            "dermis",
            "plan",
            "--profile",
            "xbox360",
            "--budget-ms",
            "2",
            "--aa",
            "smaa",
            "--validate",
            "--no-follow-surface",
        ]);
        assert!(
            n.contains(&"--aa is ignored: plan prices the skin SSS alone".to_string()),
            "{n:?}"
        );
        assert!(
            n.iter().any(|l| l.starts_with("--validate is ignored")),
            "{n:?}"
        );
        assert!(
            n.iter()
                .any(|l| l.starts_with("--no-follow-surface is ignored")),
            "{n:?}"
        );
        let n = notes(&[
            "dermis",
            "aa-eval",
            "--scene",
            "builtin:egg",
            "--assign",
            "*=none",
        ]);
        assert!(
            n.iter().any(|l| l.starts_with("--scene is ignored")),
            "{n:?}"
        );
        assert!(
            n.iter().any(|l| l.starts_with("--assign is ignored")),
            "{n:?}"
        );
        let n = notes(&["dermis", "render", "--width", "64"]);
        assert!(n.is_empty(), "{n:?}");
        let n = notes(&["dermis", "render", "--assign", "*=none", "--samples", "9"]);
        assert_eq!(
            n,
            ["--samples is ignored: --assign gives each character its method"]
        );
        assert_eq!(
            crate::app::cli::flag("follow-surface"),
            "--no-follow-surface"
        );
        assert_eq!(crate::app::cli::flag("sss_region"), "--sss-region");
    }
}
