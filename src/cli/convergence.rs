//! `glossmeter convergence`: error against run time over a sweep of tolerances. (Being written.)
use std::path::PathBuf;

use crate::Result;

/// Arguments of `glossmeter convergence`.
#[derive(clap::Args, Debug)]
pub struct ConvergenceArgs {
    /// The recipe (JSON).
    pub recipe: PathBuf,
    /// Shipped geometry ids (repeatable); default: astm-d523-20, -60, -85.
    #[arg(long = "geometry", short = 'g')]
    pub geometries: Vec<String>,
}

pub fn run(args: ConvergenceArgs) -> Result<()> {
    Err(crate::Error::Usage(format!("convergence: not implemented yet ({})", args.recipe.display())))
}
