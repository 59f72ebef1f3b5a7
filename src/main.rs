//! The `glossmeter` binary: a thin layer over the library (see `glossmeter::cli`). It wires the server
//! (`glossmeter::serve`, which stands above the command line) into `glossmeter serve`.
fn main() {
    #[cfg(feature = "serve")]
    let status = glossmeter::cli::run_with(std::env::args_os(), &glossmeter::serve::run_command);
    #[cfg(not(feature = "serve"))]
    let status = glossmeter::cli::run(std::env::args_os());
    std::process::exit(status);
}
