use std::process::ExitCode;

fn main() -> ExitCode {
    skyform::cli::main()
}
