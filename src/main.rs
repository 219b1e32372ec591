//! The `dermis` command line: everything is in the library's command wing
//! (`dermis::app`).

fn main() -> std::process::ExitCode {
    dermis::app::main()
}
