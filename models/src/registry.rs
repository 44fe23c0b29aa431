//! The older registry of the beam and membrane scenes whose studies (the beams' LCP
//! condition and locking, the membranes' inf-sup constants and profiles, the cheapest
//! pair for an accuracy) still run on the families' own programs in `src/`; every scene
//! is solved, listed and read from files through [`crate::families`].
//!
//! A scene here is its family's description ([`Scene`] for beams, [`MembraneScene`]
//! for membranes) and what the registry adds to it: the element pairs it can be solved
//! with (the first is the default) and the studies it hosts.

use crate::membrane_scenes::{MembraneScene, MEMBRANE_FLAT, MEMBRANE_SCENES};
use crate::scenes::{Beam, Scene, SCENES};
use std::borrow::Cow;

/// A model family: one solver path and one set of options per family.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// Beams on (0, 1), clamped at both ends (Timoshenko or Euler–Bernoulli).
    Beam,
    /// Membranes on triangle meshes (structured or Gmsh), `u = g` on the boundary.
    Membrane,
}

impl Family {
    /// The family's name as `list` prints it.
    pub fn name(self) -> &'static str {
        match self {
            Family::Beam => "beam",
            Family::Membrane => "membrane",
        }
    }
}

/// A scene's family description.
#[derive(Clone, Debug)]
pub enum SceneKind {
    /// A beam scene.
    Beam(Scene),
    /// A membrane scene.
    Membrane(MembraneScene),
}

/// One registry entry: the scene and what can be done with it.
#[derive(Clone, Debug)]
pub struct SceneEntry {
    /// The scene's data.
    pub kind: SceneKind,
    /// Names of the element pairs that discretize it; the first is the default.
    pub pairs: &'static [&'static str],
    /// Names of the studies it hosts (`fem-forms study <scene> <study>`).
    pub studies: &'static [&'static str],
    /// Whether the default job (`fem-forms` without a command) solves it.
    pub in_default_job: bool,
}

/// The Timoshenko pairs, default first.
pub const TIMOSHENKO_PAIRS: &[&str] = &["p2-p2-p0", "p1-p1-p0-reduced", "p1-p1-p0-full"];
/// The Euler–Bernoulli pairs.
pub const BERNOULLI_PAIRS: &[&str] = &["hermite-p0"];
/// The membrane pairs, default first.
pub const MEMBRANE_PAIRS: &[&str] = &["p2-p0", "p1-p0", "p2-p1d", "p1-nodal"];

impl SceneEntry {
    /// The scene's name.
    pub fn name(&self) -> Cow<'static, str> {
        match &self.kind {
            SceneKind::Beam(s) => Cow::Borrowed(s.name),
            SceneKind::Membrane(s) => s.name.clone(),
        }
    }

    /// One line of description.
    pub fn description(&self) -> Cow<'static, str> {
        match &self.kind {
            SceneKind::Beam(s) => Cow::Borrowed(s.description),
            SceneKind::Membrane(s) => s.description.clone(),
        }
    }

    /// The model family.
    pub fn family(&self) -> Family {
        match self.kind {
            SceneKind::Beam(_) => Family::Beam,
            SceneKind::Membrane(_) => Family::Membrane,
        }
    }

    /// The default load magnitude q of `--load` (the load is `q` times the scene's load
    /// field); `None` where the load is fixed and `--load` does not apply.
    pub fn default_load(&self) -> Option<f64> {
        match &self.kind {
            SceneKind::Beam(_) => Some(1.0),
            SceneKind::Membrane(s) => s.load_scale,
        }
    }

    /// The accuracy the scene asks for (the L² error of the primal field), where it
    /// asks for one.
    pub fn target_l2(&self) -> Option<f64> {
        match &self.kind {
            SceneKind::Beam(_) => None,
            SceneKind::Membrane(s) => Some(s.target_l2),
        }
    }
}

fn beam_entry(scene: Scene, studies: &'static [&'static str]) -> SceneEntry {
    SceneEntry {
        pairs: match scene.beam {
            Beam::Timoshenko => TIMOSHENKO_PAIRS,
            Beam::EulerBernoulli => BERNOULLI_PAIRS,
        },
        kind: SceneKind::Beam(scene),
        studies,
        in_default_job: true,
    }
}

fn membrane_entry(
    scene: MembraneScene,
    studies: &'static [&'static str],
    in_default_job: bool,
) -> SceneEntry {
    SceneEntry {
        kind: SceneKind::Membrane(scene),
        pairs: MEMBRANE_PAIRS,
        studies,
        in_default_job,
    }
}

/// The studies each built-in beam scene hosts.
fn beam_studies(name: &str) -> &'static [&'static str] {
    match name {
        "bernoulli-flat" => &[
            "convergence",
            "stability",
            "alpha",
            "work-precision",
            "iterations",
        ],
        "timoshenko-a" => &["locking", "stability", "iterations"],
        _ => &[],
    }
}

/// Every built-in scene, beams first, in the order `list` prints them.
pub fn registry() -> Vec<SceneEntry> {
    let mut entries: Vec<SceneEntry> = SCENES
        .iter()
        .map(|&s| beam_entry(s, beam_studies(s.name)))
        .collect();
    for s in MEMBRANE_SCENES {
        // work–precision needs the exact error; iterations need no exact solution
        let studies: &'static [&'static str] = match s.name.as_ref() {
            "membrane-radial" => &[
                "convergence",
                "stability",
                "alpha",
                "work-precision",
                "iterations",
            ],
            "membrane-lshape" => &["iterations"],
            _ => &[],
        };
        entries.push(membrane_entry(s, studies, true));
    }
    entries.push(membrane_entry(MEMBRANE_FLAT, &[], false));
    entries
}

/// The registry entry called `name`.
pub fn find(name: &str) -> Option<SceneEntry> {
    registry().into_iter().find(|e| e.name() == name)
}

/// The names of every registered scene, for error messages.
pub fn names() -> Vec<String> {
    registry().iter().map(|e| e.name().into_owned()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_found() {
        let names = names();
        for (k, n) in names.iter().enumerate() {
            assert!(!names[..k].contains(n), "{n} twice");
            assert_eq!(find(n).unwrap().name(), n.as_str());
        }
        assert!(find("no-such-scene").is_none());
        assert_eq!(names.len(), SCENES.len() + MEMBRANE_SCENES.len() + 1);
    }
}
