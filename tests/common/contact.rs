//! Contact problems posed as their users pose them, a scene file's text or a built-in
//! scene, and solved through the one pipeline (`families::solve`): what the Signorini
//! tests share.
#![allow(dead_code)]

use fem_forms::models::families;
use fem_forms::models::report::{Outcome, Report, Settings};
use fem_forms::models::scene_file::{self, FileScene};

/// The pressure on the blocks' tops.
pub const Q: f64 = 2.5;

/// The unit block `(0, 1)²` (E = 1000, ν = 0.3, plane strain) on the foundation below:
/// contact on the bottom, `pressure` on the top, `u_x = 0` on the left (unless
/// `boundary` replaces those lines), the initial gap `gap`; `--mesh-size n` gives n × n
/// squares.
pub fn block(pressure: &str, gap: &str, boundary: &str) -> String {
    let boundary = if boundary.is_empty() {
        "contact = \"bottom\"\n    load = \"top\"\n    fixed_x = \"left\""
    } else {
        boundary
    };
    format!(
        r#"
    model = "contact"
    [mesh]
    generator = "rectangle"
    x = [0.0, 1.0]
    y = [0.0, 1.0]
    cells = [1, 1]
    size = 2
    [material]
    young = 1000.0
    poisson = 0.3
    [boundary]
    {boundary}
    [data]
    pressure = "{pressure}"
    gap = "{gap}"
"#
    )
}

/// The block under the uniform pressure [`Q`] with no gap: the patch test, λ = Q.
pub fn patch() -> String {
    block(&Q.to_string(), "0", "")
}

/// A scene file's text, read as if from the tests' data directory.
///
/// # Panics
/// Where the text is refused.
pub fn parse(text: &str) -> FileScene {
    try_parse(text).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

/// [`parse`], the refusal returned.
pub fn try_parse(text: &str) -> fem_forms::Result<FileScene> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/scene.toml");
    scene_file::parse(text, &path)
}

/// A solved contact scene: its report and the pressure along Γ_C as steps
/// `(s0, s1, λ)` sorted along the contact plane (P0: one per edge; P1: one per vertex,
/// `s0 = s1`).
#[derive(Debug)]
pub struct Solved {
    pub report: Report,
    pub steps: Vec<(f64, f64, f64)>,
}

impl Solved {
    /// A family quantity of the report (`NaN` where null or absent).
    pub fn quantity(&self, key: &str) -> f64 {
        self.report.number(key).unwrap_or(f64::NAN)
    }

    /// λ_h per multiplier DOF, along the contact plane.
    pub fn pressures(&self) -> Vec<f64> {
        self.steps.iter().map(|s| s.2).collect()
    }
}

/// Solves a scene file with its own settings changed by `change`.
///
/// # Errors
/// The pipeline's.
pub fn solve_file(
    file: &FileScene,
    change: impl FnOnce(&mut Settings),
) -> fem_forms::Result<Solved> {
    let mut settings = file.settings();
    change(&mut settings);
    solved(families::solve(&file.scene, &settings)?)
}

/// Solves the built-in scene `name` with the settings `change` makes.
///
/// # Errors
/// The pipeline's.
pub fn solve_scene(name: &str, change: impl FnOnce(&mut Settings)) -> fem_forms::Result<Solved> {
    let scene = families::scene(name).unwrap_or_else(|| panic!("no scene `{name}`"));
    let mut settings = Settings::default();
    change(&mut settings);
    solved(families::solve(&scene, &settings)?)
}

fn solved(outcome: Outcome) -> fem_forms::Result<Solved> {
    let Outcome {
        report, profile, ..
    } = outcome;
    Ok(Solved {
        report,
        steps: profile.map(|p| p.computed.1).unwrap_or_default(),
    })
}
