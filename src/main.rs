//! The `glossmeter` binary: a thin layer over the library (see `glossmeter::cli`).
fn main() {
    std::process::exit(glossmeter::cli::run(std::env::args_os()));
}
