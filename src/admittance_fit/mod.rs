//! Fitting a passive modal bridge admittance to measured data (issue 5). Not implemented
//! yet: the command and the figure report that clearly.

use std::path::Path;

/// `colophony fit-bridge IN.csv --modes M --out OUT.json`.
pub fn run_cli(_input: &Path, _modes: usize, _out: &Path) -> Result<String, String> {
    Err("fit-bridge is not implemented yet".into())
}

/// `colophony figure bridge-fit --in IN.csv --fit OUT.json --out FILE.png`.
pub fn draw_figure(_input: &Path, _fit: &Path, _out: &Path) -> Result<String, String> {
    Err("the bridge-fit figure is not implemented yet".into())
}
