//! The coarsest uniform mesh of each pair that reaches a scene's asked accuracy, and the
//! cheapest pair among them, through the one solve: the default job's table for the
//! scenes that ask for an accuracy ([`Scene::accuracy`]). The error is estimated by
//! Richardson extrapolation from the solves on N and 2N; the a-posteriori estimators of
//! the model files are to replace it.

use crate::models::families;
use crate::models::geometry::Fields;
use crate::models::report::{Outcome, Settings};
use crate::models::scene::{Domain, Scene};
use fem_runtime::{Error, Result};
use std::collections::HashMap;

/// The coarsest N tried.
pub const COARSEST: usize = 8;

/// The finest N tried: a pair that has not reached the accuracy by then is reported as
/// not reaching it.
pub const FINEST: usize = 512;

/// One pair's way to a scene's asked accuracy.
#[derive(Clone, Debug)]
pub struct AccuracyRung {
    /// The pair.
    pub pair: &'static str,
    /// The first N whose estimated L² error is within the accuracy (or the last tried).
    pub mesh_size: usize,
    /// Unknowns at that N.
    pub dofs: usize,
    /// Wall time of the solve at that N, in seconds.
    pub seconds: f64,
    /// The Richardson estimate `‖u_N − u_2N‖ / (1 − 2⁻²)` of `‖u − u_N‖_L2`.
    pub estimated_l2: f64,
    /// The true error where an exact solution is known.
    pub exact_l2: Option<f64>,
    /// Whether the accuracy was reached (N ≤ [`FINEST`]).
    pub reached: bool,
    /// Why the pair could not be solved, if it could not.
    pub failure: Option<String>,
}

/// For every pair of `scene`, the coarsest N = 8·2^k whose estimated L² error of the
/// constrained field is within the scene's accuracy; and the index of the cheapest
/// (least solve time) that reaches it. A pair whose solves fail is a rung with its
/// failure.
///
/// # Errors
/// [`Error::Input`] for a scene that asks for no accuracy, or whose meshes are not the
/// uniform refinements of a generated domain (the estimate compares nested meshes).
pub fn cheapest_for_accuracy(scene: &Scene) -> Result<(Vec<AccuracyRung>, Option<usize>)> {
    let accuracy = scene
        .accuracy
        .ok_or_else(|| Error::Input(format!("scene `{}` asks for no accuracy", scene.name)))?;
    if !matches!(scene.domain, Domain::Rectangle { .. } | Domain::LShape) {
        return Err(Error::Input(format!(
            "scene `{}`: the accuracy table needs the nested N×N meshes of a generated rectangle or L-shape",
            scene.name
        )));
    }
    let rungs: Vec<AccuracyRung> = families::pairs_of(scene)
        .iter()
        .map(|pair| {
            rung(scene, pair.name, accuracy).unwrap_or_else(|e| AccuracyRung {
                pair: pair.name,
                mesh_size: 0,
                dofs: 0,
                seconds: f64::NAN,
                estimated_l2: f64::NAN,
                exact_l2: None,
                reached: false,
                failure: Some(e.to_string()),
            })
        })
        .collect();
    let cheapest = rungs
        .iter()
        .enumerate()
        .filter(|(_, r)| r.reached)
        .min_by(|a, b| a.1.seconds.total_cmp(&b.1.seconds))
        .map(|(k, _)| k);
    Ok((rungs, cheapest))
}

fn solve(scene: &Scene, pair: &'static str, n: usize) -> Result<Outcome> {
    let settings = Settings {
        pair: Some(pair.into()),
        mesh_size: Some(n),
        ..Settings::default()
    };
    families::solve(scene, &settings)
}

fn rung(scene: &Scene, pair: &'static str, accuracy: f64) -> Result<AccuracyRung> {
    let mut n = COARSEST;
    let mut coarse = solve(scene, pair, n)?;
    loop {
        let fine = solve(scene, pair, 2 * n)?;
        // ‖u − u_N‖ ≈ ‖u_N − u_2N‖ / (1 − 2^−p) with the L² rate p = 2
        let estimated_l2 = nested_difference(&coarse.fields, &fine.fields)? / 0.75;
        let reached = estimated_l2 <= accuracy;
        if reached || 2 * n >= FINEST {
            let s = &coarse.report.solve;
            return Ok(AccuracyRung {
                pair,
                mesh_size: n,
                dofs: s.dofs,
                seconds: s.seconds,
                estimated_l2,
                exact_l2: s.error_l2,
                reached,
                failure: None,
            });
        }
        (n, coarse) = (2 * n, fine);
    }
}

/// `‖u_c − u_f‖` of the constrained fields of two solves on nested meshes, in the
/// discrete L² norm of the coarse mesh's vertices (each weighted by a third of the area
/// of its cells: the lumped mass matrix). The vertices of the coarse mesh are vertices
/// of the fine one.
///
/// # Errors
/// [`Error::Input`] where the fields are not on triangles or a coarse vertex is not a
/// fine one.
pub fn nested_difference(coarse: &Fields, fine: &Fields) -> Result<f64> {
    let (
        Fields::Triangles {
            mesh: c, vertex: u, ..
        },
        Fields::Triangles {
            mesh: f, vertex: v, ..
        },
    ) = (coarse, fine)
    else {
        return Err(Error::Input(
            "the nested difference compares fields on triangles".into(),
        ));
    };
    let (u, v) = (&u[0].1, &v[0].1);
    let key = |p: &[f64; 2]| ((p[0] * 1e9).round() as i64, (p[1] * 1e9).round() as i64);
    let fine_index: HashMap<(i64, i64), usize> = f
        .vertices()
        .iter()
        .enumerate()
        .map(|(i, p)| (key(p), i))
        .collect();
    let mut weights = vec![0.0; c.vertices().len()];
    for (cell, vertices) in c.cells().iter().enumerate() {
        for &k in vertices {
            weights[k] += c.area(cell) / 3.0;
        }
    }
    let mut sum = 0.0;
    for (k, p) in c.vertices().iter().enumerate() {
        let j = fine_index.get(&key(p)).ok_or_else(|| {
            Error::Input(format!(
                "the coarse vertex ({}, {}) is not a vertex of the fine mesh",
                p[0], p[1]
            ))
        })?;
        sum += weights[k] * (u[k] - v[*j]).powi(2);
    }
    Ok(sum.sqrt())
}
