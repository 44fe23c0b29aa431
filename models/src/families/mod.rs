//! The registry: every model family ([`crate::family::Family`]) with its pairs, scenes
//! and own quantities, and the one entry point that solves a scene ([`solve`]).

pub mod beam;
pub mod contact;
pub mod edge_resultants;
pub mod kirchhoff;
pub mod membrane;
pub mod plate;
pub mod winkler;

use crate::family::{Family, Pair};
use crate::report::{Outcome, Settings};
use crate::scene::Scene;
use fem_runtime::{Error, Result};

/// Every family, in the order `list` prints them.
pub fn families() -> &'static [&'static dyn Family] {
    &FAMILIES
}

static FAMILIES: [&dyn Family; 6] = [
    &beam::BEAMS,
    &membrane::MEMBRANES,
    &plate::PLATES,
    &kirchhoff::KIRCHHOFF,
    &contact::CONTACT,
    &winkler::WINKLER,
];

/// The family called `name`.
pub fn family(name: &str) -> Option<&'static dyn Family> {
    families().iter().copied().find(|f| f.name() == name)
}

/// Every built-in scene, family by family.
pub fn scenes() -> Vec<Scene> {
    families().iter().flat_map(|f| f.scenes()).collect()
}

/// The built-in scene called `name`.
pub fn scene(name: &str) -> Option<Scene> {
    scenes().into_iter().find(|s| s.name == name)
}

/// The scenes a study of `scene` runs: its [`crate::scene::StudyVariant`]s, each named
/// `<scene>-<label>`, its load and its family's adjustments applied, without variants
/// of their own; `scene` itself where it has none.
///
/// # Errors
/// An adjustment the family refuses, or a scene without a family.
pub fn study_variants(scene: &Scene) -> Result<Vec<Scene>> {
    if scene.study_variants.is_empty() {
        return Ok(vec![scene.clone()]);
    }
    let family = family(scene.family)
        .ok_or_else(|| Error::Input(format!("scene `{}` has no family", scene.name)))?;
    scene
        .study_variants
        .iter()
        .map(|variant| {
            let mut posed = scene.clone();
            posed.name = format!("{}-{}", scene.name, variant.label).into();
            posed.study_variants = Vec::new();
            if let Some(q) = variant.load {
                posed.study_load = Some(q);
            }
            for adjustment in &variant.adjustments {
                family.adjust(&mut posed, adjustment)?;
            }
            Ok(posed)
        })
        .collect()
}

/// The pairs `scene` takes, its default first: those it names, else its family's.
pub fn pairs_of(scene: &Scene) -> Vec<&'static Pair> {
    let Some(family) = family(scene.family) else {
        return Vec::new();
    };
    if scene.pairs.is_empty() {
        family.pairs().iter().collect()
    } else {
        scene
            .pairs
            .iter()
            .filter_map(|name| family.pairs().iter().find(|p| p.name == *name))
            .collect()
    }
}

/// Solves `scene` with the pair `settings` name (its default otherwise); a tolerance
/// refines its mesh adaptively. [`crate::choice::solve`] also chooses the model and pair.
///
/// # Errors
/// A pair the scene's family does not have or the scene does not take, and the solve's.
pub fn solve(scene: &Scene, settings: &Settings) -> Result<Outcome> {
    if let Some((scene, settings)) = richer_parameters_moved(scene, settings) {
        return solve(&scene, &settings);
    }
    let pair = pair_of(scene, settings.pair.as_deref())?;
    (pair.solve)(pair, scene, settings)
}

/// `scene` and `settings` with the request's parameters of the family's richer model
/// ([`Family::richer_parameters`]: `--thickness` on a Kirchhoff scene) moved into the
/// scene's [`Scene::richer`], where they pose the richer neighbour and the modelling
/// estimate; `None` where the request gives none.
pub fn richer_parameters_moved(scene: &Scene, settings: &Settings) -> Option<(Scene, Settings)> {
    let names = family(scene.family)?.richer_parameters();
    let moved = |name: &str| names.contains(&name);
    if !settings.parameters.iter().any(|(name, _)| moved(name)) {
        return None;
    }
    let mut scene = scene.clone();
    let mut settings = settings.clone();
    for (name, value) in &settings.parameters {
        if moved(name) {
            scene.set_richer_parameter(name.clone(), *value);
        }
    }
    settings.parameters.retain(|(name, _)| !moved(name));
    Some((scene, settings))
}

/// The pair called `name` (`None`: the scene's default) of the scene's family.
///
/// # Errors
/// An unknown family, and a pair the scene does not take (the message lists those it
/// takes).
pub fn pair_of(scene: &Scene, name: Option<&str>) -> Result<&'static Pair> {
    let family = family(scene.family).ok_or_else(|| {
        Error::Input(format!(
            "scene `{}` is of the unknown family `{}`",
            scene.name, scene.family
        ))
    })?;
    let offered = pairs_of(scene);
    let name = match name {
        Some(name) => name,
        None => offered
            .first()
            .map(|p| p.name)
            .ok_or_else(|| Error::Input(format!("scene `{}` takes no pair", scene.name)))?,
    };
    let name = family
        .pair_aliases()
        .iter()
        .find(|(alias, _)| *alias == name)
        .map_or(name, |(_, name)| *name);
    if let Some(pair) = offered.iter().find(|p| p.name == name) {
        return Ok(pair);
    }
    let names: Vec<&str> = offered.iter().map(|p| p.name).collect();
    let other = family.pairs().iter().any(|p| p.name == name);
    Err(Error::Input(if other {
        format!(
            "pair `{name}` does not discretize scene `{}`; it takes {}",
            scene.name,
            names.join(", ")
        )
    } else if let Some(given) = richer_pair_given(scene, family, name) {
        format!(
            "pair `{name}` solves the richer model of scene `{}`, which the scene poses once given its `{}` (`{given}`); without it the scene takes {}",
            scene.name,
            family
                .aliases()
                .iter()
                .find(|(_, model_name)| *model_name == given)
                .map_or(given, |(alias, _)| *alias),
            names.join(", ")
        )
    } else {
        format!(
            "unknown pair `{name}`; scene `{}` takes {}",
            scene.name,
            names.join(", ")
        )
    }))
}

/// The richer model's parameter whose value would let `scene` take `pair` (its richer
/// neighbour's: a Kirchhoff scene's thickness poses p1-p2-p0), where one would.
pub fn richer_pair_given(scene: &Scene, family: &dyn Family, pair: &str) -> Option<&'static str> {
    let &given = family.richer_parameters().first()?;
    let mut stated = scene.clone();
    // any admissible value: the neighbour's pairs do not depend on it
    stated.set_richer_parameter(given, 1e-2);
    let richer = family.richer(&stated)?;
    pairs_of(&richer)
        .iter()
        .any(|p| p.name == pair)
        .then_some(given)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_names_are_unique_and_their_pairs_exist() {
        let scenes = scenes();
        for (k, s) in scenes.iter().enumerate() {
            assert!(
                !scenes[..k].iter().any(|t| t.name == s.name),
                "{} twice",
                s.name
            );
            assert_eq!(scene(&s.name).unwrap().name, s.name);
            assert!(family(s.family).is_some(), "{}", s.family);
            assert_eq!(pairs_of(s).len(), s.pairs.len().max(pairs_of(s).len()));
            assert!(!pairs_of(s).is_empty(), "{}", s.name);
        }
        assert!(scene("no-such-scene").is_none());
    }
}
