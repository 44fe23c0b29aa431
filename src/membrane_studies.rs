//! The membranes as the studies see them ([`StudyScene`]): a scene at its own load on
//! N×N×2 meshes, every pair, the discrete inf-sup constants as the stability measure,
//! and the multiplier along the row of cells just above the x axis.

use crate::membranes::{self, alpha_of, scene_mesh, MembranePair, MembraneReport, MembraneRequest};
use crate::models::membrane_scenes::{Domain, MembraneScene};
use crate::studies::{ExactMultiplier, Measure, Plan, Row, Run, StabilityRow, Study, StudyScene};
use fem_runtime::{Diagonal, Result};

/// A membrane scene in the studies, at its own load.
#[derive(Clone, Debug)]
pub struct MembraneStudies {
    /// The scene.
    pub scene: MembraneScene,
}

impl MembraneStudies {
    /// The studies of `scene`.
    pub fn new(scene: MembraneScene) -> Self {
        Self { scene }
    }

    /// The request of a run.
    pub fn request(&self, run: &Run) -> Result<MembraneRequest> {
        let mut request = MembraneRequest::new(self.scene.clone());
        request.pair = MembranePair::parse(run.pair)?;
        request.mesh_size = run.size;
        request.alpha = run.alpha;
        request.solver = run.solver;
        request.nested = run.nested;
        Ok(request)
    }

    /// The side of the scene's square, or of the L-shape's bounding square.
    fn side(&self) -> f64 {
        match self.scene.domain {
            Domain::Square(a) => 2.0 * a,
            _ => 2.0,
        }
    }
}

fn row(r: &MembraneReport, pair: &'static str, h: f64) -> Row {
    Row {
        pair,
        size: r.mesh_size,
        h,
        cells: r.triangles,
        dofs: r.dofs,
        alpha: r.alpha,
        error_l2: r.error_l2,
        error_h1: r.error_h1,
        error_multiplier: r.error_multiplier,
        total_contact_force: r.total_contact_force,
        force_error: r
            .exact_contact_force
            .map(|e| (r.total_contact_force - e).abs()),
        contact: r.contact_area,
        contact_error: r.exact_contact_area.map(|e| (r.contact_area - e).abs()),
        iterations: r.iterations,
        seconds: r.seconds,
        kkt_residual: r.complementarity_residual,
        warnings: r.warnings.clone(),
    }
}

/// The mesh sizes N of the convergence study for a pair: six meshes, up to
/// 512×512×2 = 524,288 triangles for the P1 pairs and 128×128×2 for P2; `full` adds
/// one finer mesh (2M triangles for P1).
pub fn convergence_sizes(pair: MembranePair, full: bool) -> Vec<usize> {
    let top = match (pair.degree(), full) {
        (1, false) => 512,
        (1, true) => 1024,
        (_, false) => 128,
        (_, true) => 256,
    };
    let mut sizes = vec![top];
    while sizes.len() < 6 + usize::from(full) {
        sizes.insert(0, sizes[0] / 2);
    }
    sizes
}

impl StudyScene for MembraneStudies {
    fn name(&self) -> String {
        self.scene.name.to_string()
    }

    fn setting(&self) -> String {
        self.name()
    }

    fn size_name(&self) -> &'static str {
        "N"
    }

    fn h(&self, size: usize) -> f64 {
        self.side() * 2f64.sqrt() / size as f64
    }

    fn contact_names(&self) -> [&'static str; 2] {
        ["contact area", "area error"]
    }

    fn pairs(&self) -> Vec<&'static str> {
        MembranePair::ALL.map(MembranePair::name).to_vec()
    }

    fn plan(&self, study: Study, pair: &'static str, full: bool) -> Plan {
        let p2 = MembranePair::P2P0.name();
        let plan = |pair, sizes, cold_max, alphas| Plan {
            pair,
            sizes,
            cold_max,
            alphas,
        };
        let profile_n = if full { 64 } else { 32 };
        match study {
            Study::Convergence => plan(
                pair,
                convergence_sizes(
                    MembranePair::parse(pair).unwrap_or(MembranePair::P2P0),
                    full,
                ),
                0,
                vec![],
            ),
            Study::Stability => {
                let mut sizes = vec![2, 4, 6, 8, 12, 16];
                if full {
                    sizes.extend([20, 24]);
                }
                plan(pair, sizes, 0, vec![])
            }
            Study::Alpha => plan(
                p2,
                vec![profile_n],
                0,
                (0..=24)
                    .map(|k| Some(10f64.powf(-6.0 + 0.2 * k as f64)))
                    .chain([Some(0.0)])
                    .collect(),
            ),
            Study::WorkPrecision => plan(
                p2,
                if full {
                    vec![8, 16, 32, 64, 128]
                } else {
                    vec![8, 16, 32]
                },
                usize::MAX,
                vec![],
            ),
            Study::Iterations => plan(
                p2,
                if full {
                    vec![8, 16, 32, 64, 128, 256]
                } else {
                    vec![8, 16, 32, 64]
                },
                if full { 128 } else { 64 },
                vec![],
            ),
            Study::Locking => plan(pair, vec![], 0, vec![]),
        }
    }

    fn profiles(&self, full: bool) -> Plan {
        Plan {
            pair: MembranePair::P2P0.name(),
            sizes: vec![if full { 64 } else { 32 }],
            cold_max: 0,
            alphas: vec![Some(0.0), None],
        }
    }

    fn solve(&self, run: &Run) -> Result<Row> {
        let (report, _) = membranes::solve(&self.request(run)?)?;
        Ok(row(&report, run.pair, self.h(run.size)))
    }

    fn inverse_constant(&self, pair: &'static str, size: usize) -> Result<f64> {
        let mesh = scene_mesh(&self.scene, size, Diagonal::Right)?;
        Ok(alpha_of(&self.request(&Run::new(pair, size))?, &mesh)?.1)
    }

    fn exact_contact(&self) -> Option<f64> {
        let load = self.scene.load_magnitude(None).ok()?;
        self.scene.exact_at(load)?.contact_area
    }

    fn stability_pairs(&self) -> Vec<&'static str> {
        vec![MembranePair::P1P0.name(), MembranePair::P2P0.name()]
    }

    fn measure(&self) -> Measure {
        crate::studies::inf_sup_measure()
    }

    /// The one measure of every family, on the registry's scene of this name.
    fn stability(&self, pair: &'static str, size: usize) -> Result<StabilityRow> {
        crate::registry_studies::RegistryStudies::of(&self.scene.name)?.stability(pair, size)
    }

    /// `(x, λ_h)` at the centroids of the cells in the band `0 < y < side/N` (the row of
    /// cells just above the x axis).
    fn multiplier_profile(&self, run: &Run) -> Result<Vec<(f64, f64)>> {
        let (_, fields) = membranes::solve(&self.request(run)?)?;
        let band = self.side() / run.size as f64;
        let mut points: Vec<(f64, f64)> = (0..fields.mesh.cell_count())
            .filter_map(|c| {
                let x = fields.mesh.cell_coordinates(c);
                let (cx, cy) = ((x[0] + x[2] + x[4]) / 3.0, (x[1] + x[3] + x[5]) / 3.0);
                (cy > 0.0 && cy < band).then_some((cx, fields.lambda[c]))
            })
            .collect();
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        Ok(points)
    }

    /// The exact λ on the x axis, and the contact interval there (where it is positive).
    fn exact_multiplier(&self) -> Option<ExactMultiplier> {
        let load = self.scene.load_magnitude(None).ok()?;
        let multiplier = self.scene.exact_at(load)?.multiplier?;
        let half = 0.5 * self.side();
        let touching: Vec<f64> = (0..=4000)
            .map(|i| -half + 2.0 * half * i as f64 / 4000.0)
            .filter(|&x| multiplier.at(&[x, 0.0]) > 0.0)
            .collect();
        let contact = [*touching.first()?, *touching.last()?];
        Some(ExactMultiplier {
            contact,
            lambda: Box::new(move |x| multiplier.at(&[x, 0.0])),
        })
    }

    fn profile_window(&self) -> [f64; 2] {
        [-0.25 * self.side(), 0.25 * self.side()]
    }
}
