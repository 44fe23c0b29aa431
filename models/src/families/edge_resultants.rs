//! The stress resultants of a plate along its boundary, where a scene asks for them
//! (`--edge-resultants`, a scene file's `edge_resultants = true`): the bending moment
//! `M_nn`, the twisting moment `M_ns` and the shear force, for the Reissner–Mindlin and
//! the Kirchhoff plate alike, and the boundary layer that separates the two.
//!
//! Sign convention of both models: `M = D[(1−ν)ε(θ) + ν tr ε(θ) I]` with `θ = ∇w` for
//! Kirchhoff, the shear force `Q = −div M` (Reissner–Mindlin: `Q = S(∇w − θ)`, its
//! rotation equation; Kirchhoff: `Q = −D∇Δw`), `n` the outward normal and `τ` the
//! tangent, `M_nn = n·M·n`, `M_ns = n·M·τ`, `Q_n = Q·n`.
//!
//! Where the Mindlin rotations are free on the boundary (a free edge, a soft simple
//! support) the Mindlin twisting moment vanishes on the edge and the Kirchhoff one does
//! not: a layer of width `δ = t/√(12κ)` (Arnold–Falk) turns one into the other, across
//! which the Mindlin shear force `Q_n` gains `−∂_s M_ns`. On the edge the Mindlin shear
//! force is therefore Kirchhoff's *effective* shear `V_n = Q_n − ∂_s M_ns` (Kirchhoff's
//! reaction per unit length, Timoshenko and Woinowsky-Krieger §22 in the opposite sign of
//! M), which is what the Kirchhoff report gives as its shear force; Kirchhoff's corner
//! forces, which the Mindlin layer spreads along the edges near each corner, are not in
//! its `shear_force_integral`. The Kirchhoff plate can report neither the Mindlin edge's
//! `M_ns = 0` nor the distribution of its reaction near corners: a scene asking for the
//! edge resultants of a plate with such edges is not given the Kirchhoff model on
//! thickness alone ([`twisting_share`]), and the Mindlin mesh is refined along those
//! edges until its boundary cells are no longer than `δ`
//! ([`fem_runtime::adaptivity::BoundaryLayer`]).

use crate::geometry::Geometry;
use crate::scene::{Scene, Support};
use fem_runtime::adaptivity::BoundaryLayer;
use fem_runtime::element::triangle::{AffineMap, TriangleBasis, TriangleField};
use fem_runtime::TriangleMesh;
use serde::Serialize;

/// The width `δ = t/√(12κ)` of the Reissner–Mindlin rotations' boundary layer
/// (Arnold–Falk 1989): the decay length of `φ″ = φ/δ²`, from `D(1−ν)/2 φ″ = S φ` with
/// `S = 6κ(1−ν)D/t²`.
pub fn layer_width(t: f64, kappa: f64) -> f64 {
    t / (12.0 * kappa).sqrt()
}

/// The boundary markers of `mesh` whose edges leave the Mindlin rotations free: those
/// the scene's supports leave free or hold by a soft simple support (`w = 0` alone).
/// Supports combine where their parts overlap, as the solve's conditions do (an edge
/// holds every condition of every support naming it; `free` adds none): an edge is
/// rotation-free when every support naming it is free or soft, or none names it.
pub fn rotations_free_markers(scene: &Scene, mesh: &TriangleMesh) -> Vec<u32> {
    let parts: Vec<(fem_runtime::DirichletPart, Support)> = scene
        .supports
        .iter()
        .filter_map(|s| Some((mesh.part(&s.part).ok()?, s.support)))
        .collect();
    let mut markers: Vec<u32> = mesh
        .boundary_edges()
        .iter()
        .map(|&(_, marker)| marker)
        .filter(|&marker| {
            parts
                .iter()
                .filter(|(part, _)| part.contains(marker))
                .all(|(_, support)| {
                    matches!(
                        support,
                        Support::Free | Support::SimplySupported { hard: false }
                    )
                })
        })
        .collect();
    markers.sort_unstable();
    markers.dedup();
    markers
}

/// The Reissner–Mindlin boundary layer of `scene` on `mesh` for an adaptive solve that
/// must resolve it: `None` where the scene does not ask for its edge resultants or no
/// edge leaves the rotations free.
pub fn boundary_layer(
    scene: &Scene,
    mesh: &TriangleMesh,
    t: f64,
    kappa: f64,
) -> Option<BoundaryLayer> {
    if !scene.edge_resultants {
        return None;
    }
    let markers = rotations_free_markers(scene, mesh);
    (!markers.is_empty()).then(|| BoundaryLayer {
        width: layer_width(t, kappa),
        markers,
    })
}

/// The resultants along the boundary, sampled at the midpoint of each boundary edge,
/// with their extremes and the reaction.
#[derive(Clone, Debug, Default, Serialize)]
pub struct EdgeResultants {
    /// What `shear_force` is: the Mindlin `Q·n`, or Kirchhoff's effective shear.
    pub shear_force_kind: &'static str,
    /// `δ = t/√(12κ)`, where the plate has a thickness.
    pub layer_width: Option<f64>,
    /// The longest boundary edge among those that leave the rotations free; `None`
    /// where none does.
    pub layer_longest_edge: Option<f64>,
    /// Whether the mesh resolves the layer: every boundary edge that leaves the rotations
    /// free is no longer than `δ` (`None` for the Kirchhoff plate, which has no layer,
    /// and where no edge leaves the rotations free).
    pub layer_resolved: Option<bool>,
    /// `max |M_nn|` over the boundary edges' midpoints.
    pub bending_moment_max: f64,
    /// `max |M_ns|` over the midpoints of the edges that leave the rotations free
    /// (0 where none does).
    pub twisting_moment_max: f64,
    /// `max |shear force|` over the boundary edges' midpoints.
    pub shear_force_max: f64,
    /// `∫_∂Ω shear force ds`: the supports' reaction, `−∫ f` less the contact force
    /// for the Mindlin plate, to the discretization; the Kirchhoff plate's leaves out its
    /// corner forces.
    pub shear_force_integral: f64,
    /// The samples, one per boundary edge: its midpoint, marker, and the resultants there.
    pub profile: Profile,
}

/// The resultants at the boundary edges' midpoints (force per unit length for the shear,
/// moment per unit length for `M`).
#[derive(Clone, Debug, Default, Serialize)]
pub struct Profile {
    /// x of each midpoint.
    pub x: Vec<f64>,
    /// y of each midpoint.
    pub y: Vec<f64>,
    /// The boundary marker of each edge.
    pub marker: Vec<u32>,
    /// The length of each edge (the weights of `∫ ds` by the midpoint rule).
    pub length: Vec<f64>,
    /// `M_nn`.
    pub m_nn: Vec<f64>,
    /// `M_ns`.
    pub m_ns: Vec<f64>,
    /// The shear force (`Q·n`, or Kirchhoff's `V_n`).
    pub shear_force: Vec<f64>,
}

/// One boundary edge: its cell, the cell's map, the edge's end points, length, outward
/// normal and tangent (the normal turned counter-clockwise, so that the boundary is
/// walked with the domain on the left and `M_ns` does not depend on the order in which
/// the mesh stores the edge's vertices).
struct Edge {
    cell: usize,
    map: AffineMap,
    ends: [[f64; 2]; 2],
    length: f64,
    normal: [f64; 2],
    tangent: [f64; 2],
    marker: u32,
}

fn boundary_edges(mesh: &TriangleMesh) -> impl Iterator<Item = Edge> + '_ {
    mesh.boundary_edges().iter().map(move |&(e, marker)| {
        let (cell, _) = mesh.edge_cells(e);
        let ends = mesh.edges()[e].map(|v| mesh.vertices()[v]);
        let [a, b] = ends;
        let length = (b[0] - a[0]).hypot(b[1] - a[1]);
        let along = [(b[0] - a[0]) / length, (b[1] - a[1]) / length];
        // outward: away from the cell's third vertex
        let centre = {
            let x = mesh.cell_coordinates(cell);
            [(x[0] + x[2] + x[4]) / 3.0, (x[1] + x[3] + x[5]) / 3.0]
        };
        let mut normal = [along[1], -along[0]];
        if normal[0] * (a[0] - centre[0]) + normal[1] * (a[1] - centre[1]) < 0.0 {
            normal = [-normal[0], -normal[1]];
        }
        let tangent = [-normal[1], normal[0]];
        Edge {
            cell,
            map: AffineMap::of(mesh, cell),
            ends,
            length,
            normal,
            tangent,
            marker,
        }
    })
}

/// Samples every boundary edge of `mesh` at its midpoint: `at` gives the moment tensor
/// and the shear force there (from the edge's cell and the midpoint's reference
/// coordinates); also the longest edge among those of `layered`.
fn sample(
    mesh: &TriangleMesh,
    layered: &[u32],
    mut at: impl FnMut(&Edge, [f64; 2]) -> ([[f64; 2]; 2], f64),
) -> (Profile, Option<f64>) {
    let mut profile = Profile::default();
    let mut longest: Option<f64> = None;
    for edge in boundary_edges(mesh) {
        let [a, b] = edge.ends;
        let mid = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
        let (m, shear) = at(&edge, edge.map.reference_point(mid));
        if layered.contains(&edge.marker) {
            longest = Some(longest.unwrap_or(0.0).max(edge.length));
        }
        profile.x.push(mid[0]);
        profile.y.push(mid[1]);
        profile.marker.push(edge.marker);
        profile.m_nn.push(bilinear(m, edge.normal, edge.normal));
        profile.m_ns.push(bilinear(m, edge.normal, edge.tangent));
        profile.shear_force.push(shear);
        profile.length.push(edge.length);
    }
    (profile, longest)
}

fn bilinear(m: [[f64; 2]; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (0..2)
        .map(|i| (0..2).map(|j| a[i] * m[i][j] * b[j]).sum::<f64>())
        .sum()
}

/// `D[(1−ν)e + ν tr e I]` of a symmetric strain `e`.
fn moment(e: [[f64; 2]; 2], d: f64, nu: f64) -> [[f64; 2]; 2] {
    let trace = e[0][0] + e[1][1];
    [
        [
            d * ((1.0 - nu) * e[0][0] + nu * trace),
            d * (1.0 - nu) * e[0][1],
        ],
        [
            d * (1.0 - nu) * e[1][0],
            d * ((1.0 - nu) * e[1][1] + nu * trace),
        ],
    ]
}

/// Gathers the samples into the extremes and the reaction (`∫` by the midpoint rule on
/// each edge: exact for the Mindlin pair's linear shear force).
fn summarize(profile: Profile, layered: &[u32], kind: &'static str) -> EdgeResultants {
    let abs_max = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let twisting_moment_max = profile
        .m_ns
        .iter()
        .zip(&profile.marker)
        .filter(|(_, m)| layered.contains(m))
        .fold(0.0f64, |m, (x, _)| m.max(x.abs()));
    EdgeResultants {
        shear_force_kind: kind,
        bending_moment_max: abs_max(&profile.m_nn),
        twisting_moment_max,
        shear_force_max: abs_max(&profile.shear_force),
        shear_force_integral: profile
            .shear_force
            .iter()
            .zip(&profile.length)
            .map(|(q, l)| q * l)
            .sum(),
        profile,
        ..EdgeResultants::default()
    }
}

/// The parameters of a Reissner–Mindlin solution's resultants: `D`, `ν`, `κ`, `t` and the
/// Stenberg `β` of its shear weight `6κ(1−ν)D/(t² + β h_T²)` (0 for the plain pair).
#[derive(Clone, Copy, Debug)]
pub struct MindlinParameters {
    /// Bending stiffness.
    pub d: f64,
    /// Poisson's ratio.
    pub nu: f64,
    /// Shear correction.
    pub kappa: f64,
    /// Thickness.
    pub t: f64,
    /// Stenberg's β (0: the physical shear weight).
    pub beta: f64,
}

/// The edge resultants of a Reissner–Mindlin solution (`theta` its two rotation fields,
/// `w` its deflection), `layered` the markers of the edges that leave its rotations free.
/// The shear force is the discrete one of the solve, `S_T(∇w_h − θ_h)·n` with the
/// pair's weight.
pub fn mindlin(
    theta: [&TriangleField<'_>; 2],
    w: &TriangleField<'_>,
    p: MindlinParameters,
    layered: &[u32],
) -> EdgeResultants {
    let [bx, by] = theta.map(|f| TriangleBasis::new(f.map.element()));
    let bw = TriangleBasis::new(w.map.element());
    let (profile, longest) = sample(w.mesh, layered, |edge, xi| {
        let (c, map) = (edge.cell, &edge.map);
        let (gx, gy) = (
            theta[0].gradient(&bx, map, c, xi),
            theta[1].gradient(&by, map, c, xi),
        );
        let off = 0.5 * (gx[1] + gy[0]);
        let m = moment([[gx[0], off], [off, gy[1]]], p.d, p.nu);
        let h = w.mesh.cell_diameter(c);
        let weight = 6.0 * p.kappa * (1.0 - p.nu) * p.d / (p.t * p.t + p.beta * h * h);
        let g = w.gradient(&bw, map, c, xi);
        let q = [
            weight * (g[0] - theta[0].value(&bx, c, xi)),
            weight * (g[1] - theta[1].value(&by, c, xi)),
        ];
        (m, q[0] * edge.normal[0] + q[1] * edge.normal[1])
    });
    let width = layer_width(p.t, p.kappa);
    EdgeResultants {
        layer_width: Some(width),
        layer_longest_edge: longest,
        layer_resolved: longest.map(|l| l <= width),
        ..summarize(profile, layered, "Q·n, Q = S_T(∇w_h − θ_h)")
    }
}

/// The edge resultants of a Kirchhoff deflection `w` (an element with third
/// derivatives: Argyris), `layered` the edges where a Mindlin plate of the same
/// supports would have its layer, `layer` its width where the scene has a thickness.
/// The shear force is the effective shear `V_n = Q_n − ∂_s M_ns`,
/// `Q = −D∇Δw`.
pub fn kirchhoff(
    w: &TriangleField<'_>,
    d: f64,
    nu: f64,
    layered: &[u32],
    layer: Option<f64>,
) -> EdgeResultants {
    let basis = TriangleBasis::new(w.map.element());
    let (profile, longest) = sample(w.mesh, layered, |edge, xi| {
        let (c, map) = (edge.cell, &edge.map);
        let m = moment(w.hessian(&basis, map, c, xi), d, nu);
        let third = w.third_derivatives(&basis, map, c, xi);
        let grad_laplacian = [0, 1].map(|i| third[i][0][0] + third[i][1][1]);
        let q_n = -d * (grad_laplacian[0] * edge.normal[0] + grad_laplacian[1] * edge.normal[1]);
        // ∂_s M_ns = D(1−ν) Σ n_i τ_j τ_k ∂_ijk w
        let twist_slope = d
            * (1.0 - nu)
            * third
                .iter()
                .zip(edge.normal)
                .map(|(third_i, n)| n * bilinear(*third_i, edge.tangent, edge.tangent))
                .sum::<f64>();
        (m, q_n - twist_slope)
    });
    EdgeResultants {
        layer_width: layer,
        layer_longest_edge: longest,
        ..summarize(
            profile,
            layered,
            "Kirchhoff's effective shear V_n = Q_n − ∂_s M_ns, Q = −D∇Δw (corner forces not included)",
        )
    }
}

/// The Kirchhoff twisting moment on the edges where a Mindlin plate's rotations are
/// free, relative to the boundary moments: `‖M_ns‖_{L²(Γ_free)} / ‖(M_nn, M_ns)‖_{L²(∂Ω)}`
/// from the samples. The Mindlin edge has `M_ns = 0` there, so this is the relative
/// modelling error of the Kirchhoff plate's edge moments (1 where every edge leaves the
/// rotations free and `M_nn` vanishes on them, as on soft simple supports); 0 where no
/// edge does.
pub fn twisting_share(resultants: &EdgeResultants, layered: &[u32]) -> f64 {
    let p = &resultants.profile;
    let (mut free, mut all) = (0.0, 0.0);
    for k in 0..p.x.len() {
        let m2 = p.length[k] * p.m_ns[k] * p.m_ns[k];
        all += m2 + p.length[k] * p.m_nn[k] * p.m_nn[k];
        if layered.contains(&p.marker[k]) {
            free += m2;
        }
    }
    if all > 0.0 {
        (free / all).sqrt()
    } else {
        0.0
    }
}
