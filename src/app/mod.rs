//! The command wing (issue 27): the clap tree (`cli`), the one checked
//! request every command builds before any device opens (`request`), the
//! notes on options a command does not read (`notes`), and one file per
//! subcommand. The commands that open a device live here; the library below
//! (`run`, `render`, `eval`, `budget`, `plan`) takes checked values and
//! checks nothing again.

pub mod aa_eval;
pub mod bench;
pub mod budget;
pub mod cli;
pub mod compare;
pub mod devices;
pub mod eval;
pub mod kernel;
pub mod methods;
pub mod notes;
pub mod plan;
pub mod plan_check;
pub mod plan_motion;
pub mod reference;
pub mod render;
pub mod request;
pub mod truth;

use std::process::ExitCode;

use anyhow::Result;
use clap::{CommandFactory, FromArgMatches};

use cli::{Cli, Command};
use request::Given;

/// Parses the command line, names the options the command does not read,
/// runs the command; an error is one line on standard error (the error and
/// its causes) and exit status 1.
pub fn main() -> ExitCode {
    let result = run_command_line();
    if std::env::var_os("DERMIS_CHECK_COUNTS").is_some() {
        eprintln!("{}", crate::checks::line());
    }
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", format!("{e:#}").replace('\n', " | "));
            ExitCode::FAILURE
        }
    }
}

fn run_command_line() -> Result<()> {
    let matches = Cli::command().get_matches();
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    let given = matches
        .subcommand()
        .map(|(_, sub)| Given::of(sub))
        .unwrap_or_default();
    for note in notes::ignored(&cli.command, &given) {
        eprintln!("note: {note}");
    }
    run(&cli.command, &given)
}

/// Runs one parsed command (`given`: the options its command line gave).
pub fn run(command: &Command, given: &Given) -> Result<()> {
    match command {
        Command::Render(a) => render::run(a, given),
        Command::Bench(a) => bench::run(a, given),
        Command::Reference(a) => reference::run(a, given),
        Command::Compare(a) => compare::run(a),
        Command::Eval(a) => eval::run(a, given),
        Command::AaEval(a) => aa_eval::run(a, given),
        Command::Budget(a) => budget::run(a, given),
        Command::Plan(a) => plan::run(a, given),
        Command::PlanCheck(a) => plan_check::run(a, given),
        Command::PlanMotion(a) => plan_motion::run(a, given),
        Command::Kernel(a) => kernel::run(a),
        Command::Devices(a) => devices::run(a),
        Command::Methods(a) => methods::run(a),
    }
}
