//! Reading Gmsh `.msh` files into triangle meshes.
//!
//! The parser is `mshio`, which reads the MSH 4.1 format (ASCII and binary) only; files
//! in the older 2.2 format are rejected with a hint to re-export them as 4.1.

use std::path::Path;

use mshio::{ElementType, MshFile};

use crate::error::{Error, Result};
use crate::mesh::triangle::{NamedGroup, QuadraticGeometry, TriangleMesh};

/// Reads a Gmsh `.msh` file (MSH 4.1, ASCII or binary) into a [`TriangleMesh`].
///
/// See [`parse_msh`] for what is read and what is rejected.
pub fn read_msh(path: &Path) -> Result<TriangleMesh> {
    let bytes = std::fs::read(path)
        .map_err(|e| Error::Io(format!("cannot read {}: {e}", path.display())))?;
    parse_msh(&bytes).map_err(|e| match e {
        Error::Mesh(message) => Error::Mesh(format!("{}: {message}", path.display())),
        other => other,
    })
}

/// Parses the contents of a Gmsh `.msh` file (MSH 4.1, ASCII or binary) into a [`TriangleMesh`].
///
/// 3-node triangles (Gmsh type 2) become the cells and 2-node lines (type 1) on boundary
/// edges give the boundary markers. Lines on interior edges (embedded curves) are
/// ignored, and so are point elements. Nodes no triangle uses are dropped and the rest
/// numbered compactly in increasing tag order. All nodes must lie in the plane `z = 0`
/// (up to 1e-12 of the mesh's extent). The `$PhysicalNames` section (ASCII in ASCII and
/// binary files alike) names the mesh's groups ([`TriangleMesh::named_groups`]): a named
/// curve group (dimension 1) is a boundary part, the boundary edges of its curves; point
/// and surface names are kept so that choosing them as boundary parts is a clear error.
/// A boundary edge may be in several groups, through a curve in several physical groups
/// or through several curves listing the same edge (as writers of one curve per group
/// do), and each group is exactly its edges: the edges of each distinct combination of
/// groups get a marker of their own, the lowest physical tag of the combination (a
/// curve in no group: its own tag) unless another combination has it, else a new one
/// above every tag in the file. Each clockwise triangle (of a surface whose
/// normal is −z) is made counter-clockwise by itself, so surfaces of opposite normals
/// can be mixed. Parametric node coordinates (`Mesh.SaveParametric = 1`) are dropped
/// from ASCII files; binary files with them are refused with that hint.
///
/// # Errors
/// [`Error::Mesh`] naming the Gmsh element or node at fault, for anything
/// [`TriangleMesh::new`] refuses (degenerate, duplicate or overlapping cells), and for
/// a mesh with a cut inside its domain: coincident nodes
/// ([`TriangleMesh::coincident_vertices`]) or a node hanging on another surface's
/// boundary edge ([`TriangleMesh::vertices_on_boundary_edges`]), as Gmsh writes when two
/// surfaces are meshed without sharing their common curve. Those are refused, not
/// merged, with the Gmsh fix (`Coherence`) in the message: merging would silently
/// change the model, whose author may have meant a slit.
pub fn parse_msh(bytes: &[u8]) -> Result<TriangleMesh> {
    Ok(parse(bytes, false)?.0)
}

/// Reads a Gmsh `.msh` file of second-order (6-node, Gmsh type 9) triangles into a
/// [`TriangleMesh`] of their corners and the [`QuadraticGeometry`] of their edge nodes:
/// the isoparametric cells Gmsh meshed with `Mesh.ElementOrder = 2` (curved where the
/// model's boundary is).
///
/// # Errors
/// As [`parse_msh_quadratic`].
pub fn read_msh_quadratic(path: &Path) -> Result<(TriangleMesh, QuadraticGeometry)> {
    let bytes = std::fs::read(path)
        .map_err(|e| Error::Io(format!("cannot read {}: {e}", path.display())))?;
    parse_msh_quadratic(&bytes).map_err(|e| match e {
        Error::Mesh(message) => Error::Mesh(format!("{}: {message}", path.display())),
        other => other,
    })
}

/// Parses a `.msh` file of 6-node triangles (with 3-node boundary lines): everything
/// [`parse_msh`] reads and checks, on the triangles' corners, plus the edge nodes as
/// [`QuadraticGeometry`] (Gmsh's node order: corners, then the nodes of edges 0–1, 1–2,
/// 2–0).
///
/// # Errors
/// Those of [`parse_msh`]; a file of 3-node triangles (read it with [`parse_msh`]) or
/// of both kinds; two triangles that give one edge different nodes; an edge node that
/// is not defined or not in the plane; a cell whose quadratic map folds
/// ([`QuadraticGeometry::from_edge_nodes`]).
pub fn parse_msh_quadratic(bytes: &[u8]) -> Result<(TriangleMesh, QuadraticGeometry)> {
    let (mesh, geometry) = parse(bytes, true)?;
    let geometry = geometry.ok_or_else(|| {
        Error::Mesh(
            "the file has 3-node triangles: it is a first-order mesh (read it as one), not a quadratic geometry".into(),
        )
    })?;
    Ok((mesh, geometry))
}

/// The shared reader: with `quadratic`, 6-node triangles are read (and 3-node ones are
/// not) and their edge nodes returned as the geometry.
fn parse(bytes: &[u8], quadratic: bool) -> Result<(TriangleMesh, Option<QuadraticGeometry>)> {
    let binary = check_header(bytes)?;
    let stripped = if binary {
        None
    } else {
        strip_parametric(bytes)
    };
    let bytes = stripped.as_deref().unwrap_or(bytes);
    let file = parse_with_mshio(bytes)?;
    let nodes = node_table(&file, if binary { None } else { ascii_node_tags(bytes) })?;
    let elements = collect_elements(&file, quadratic)?;
    let names = physical_names(bytes)?;

    // compact numbering of the nodes the triangles use, in increasing tag order
    let mut used: Vec<u64> = elements.triangles.iter().flat_map(|t| t.1).collect();
    used.sort_unstable();
    used.dedup();
    let mut vertices = Vec::with_capacity(used.len());
    let mut zs = Vec::with_capacity(used.len());
    for &tag in &used {
        let Some(p) = nodes.get(tag) else {
            let (element, _) = elements
                .triangles
                .iter()
                .find(|t| t.1.contains(&tag))
                .copied()
                .unwrap_or((0, [0; 3]));
            return Err(Error::Mesh(format!(
                "element {element} references node {tag}, which the $Nodes section does not define"
            )));
        };
        vertices.push([p[0], p[1]]);
        zs.push(p[2]);
    }
    check_planar(&vertices, &zs, &used)?;
    let index = |tag: u64| used.binary_search(&tag).ok();
    let mut cells: Vec<[usize; 3]> = elements
        .triangles
        .iter()
        .map(|(_, t)| t.map(|tag| index(tag).unwrap_or(usize::MAX)))
        .collect();
    orient(&vertices, &mut cells);

    let element_of_cell: Vec<u64> = elements.triangles.iter().map(|t| t.0).collect();
    let annotate = |e: Error| match e {
        Error::Mesh(message) => Error::Mesh(annotate_indices(&message, &element_of_cell, &used)),
        other => other,
    };
    let mut mesh = TriangleMesh::new(vertices, cells, &[]).map_err(annotate)?;
    refuse_duplicate_nodes(&mesh).map_err(annotate)?;

    // what the lines say about each boundary edge: a curve may be in several physical
    // groups, and an edge may be listed by several curves (one per group, as MSH 2
    // writers and some exporters do)
    let curves = file
        .data
        .entities
        .as_ref()
        .map_or(&[][..], |e| e.curves.as_slice());
    let mut groups_of_curve: std::collections::HashMap<i32, &[i32]> = Default::default();
    for c in curves {
        if groups_of_curve.insert(c.tag, &c.physical_tags).is_some() {
            return Err(Error::Mesh(format!(
                "curve {} is listed twice in the $Entities section: its physical groups would be ambiguous",
                c.tag
            )));
        }
    }
    let mut labelled: Vec<(usize, [usize; 2], Vec<Label>)> = Vec::new();
    let mut interior: std::collections::HashSet<(i32, usize)> = Default::default();
    let mut slot_of_edge: std::collections::HashMap<usize, usize> = Default::default();
    for &(element, [n0, n1], curve) in &elements.lines {
        for n in [n0, n1] {
            if nodes.get(n).is_none() {
                return Err(Error::Mesh(format!(
                    "element {element} references node {n}, which the $Nodes section does not define"
                )));
            }
        }
        let (Some(a), Some(b)) = (index(n0), index(n1)) else {
            return Err(Error::Mesh(format!(
                "line element {element} (nodes {n0}, {n1}) is not an edge of the triangles: one of its nodes belongs to no triangle"
            )));
        };
        let Some(edge) = mesh.find_edge(a, b) else {
            return Err(Error::Mesh(format!(
                "line element {element} (nodes {n0}, {n1}) is not an edge of the triangles"
            )));
        };
        let groups = groups_of_curve.get(&curve).copied().unwrap_or(&[]);
        // Lines on interior edges belong to embedded curves, which carry no boundary
        // marker; their groups count them, to warn where such a group is a boundary part.
        if mesh.edge_cells(edge).1.is_some() {
            for &g in groups {
                interior.insert((g, edge));
            }
            continue;
        }
        let labels: Vec<Label> = if groups.is_empty() {
            vec![Label::Curve(curve)]
        } else {
            groups.iter().map(|&g| Label::Group(g)).collect()
        };
        // a negative tag (which Gmsh does not write) cannot be a marker: its set gets a new one
        for label in labels {
            let slot = *slot_of_edge.entry(edge).or_insert_with(|| {
                labelled.push((edge, [a, b], Vec::new()));
                labelled.len() - 1
            });
            let set = &mut labelled[slot].2;
            if !set.contains(&label) {
                set.push(label);
            }
        }
    }
    let sets = LabelSets::new(&mut labelled, &file, &names)?;
    let markers: Vec<(usize, usize, u32)> = labelled
        .iter()
        .map(|(_, [a, b], set)| (*a, *b, sets.marker(set)))
        .collect();
    mesh.apply_markers(&markers).map_err(annotate)?;
    mesh.set_named_groups(named_groups(&file, &names, &sets, &interior));
    if elements.edge_nodes.is_empty() {
        return Ok((mesh, None));
    }
    let geometry = quadratic_geometry(&mesh, &elements, &nodes, &used).map_err(annotate)?;
    Ok((mesh, Some(geometry)))
}

/// The edge nodes of 6-node triangles as the geometry of `mesh` (whose vertex `i` is the
/// node tagged `used[i]`): looked up by each edge's pair of corners, so that the cells
/// `orient` turned keep their nodes, and checked to agree between neighbours.
fn quadratic_geometry(
    mesh: &TriangleMesh,
    elements: &Elements,
    nodes: &NodeTable,
    used: &[u64],
) -> Result<QuadraticGeometry> {
    let mut edge_nodes = vec![None; mesh.edge_count()];
    let index = |tag: u64| used.binary_search(&tag).ok();
    for (&(element, corners), &(_, middles)) in elements.triangles.iter().zip(&elements.edge_nodes)
    {
        for k in 0..3 {
            let (a, b, middle) = (corners[k], corners[(k + 1) % 3], middles[k]);
            let p = nodes.get(middle).ok_or_else(|| {
                Error::Mesh(format!(
                    "element {element} references node {middle}, which the $Nodes section does not define"
                ))
            })?;
            if !(p[2] == 0.0 || p[2].abs() <= 1e-12 * (p[0].abs() + p[1].abs()).max(1.0)) {
                return Err(Error::Mesh(format!(
                    "node {middle} has z = {}: only meshes in the plane z = 0 are supported",
                    p[2]
                )));
            }
            let edge = match (index(a), index(b)) {
                (Some(a), Some(b)) => mesh.find_edge(a, b),
                _ => None,
            }
            .ok_or_else(|| {
                Error::Mesh(format!(
                    "element {element}: nodes {a} and {b} do not form an edge of the mesh"
                ))
            })?;
            let node = [p[0], p[1]];
            match edge_nodes[edge] {
                None => edge_nodes[edge] = Some((node, middle)),
                Some((other, tag)) if other != node => {
                    return Err(Error::Mesh(format!(
                        "the edge between nodes {a} and {b} has two different middle nodes, {tag} and {middle} (element {element}): the triangles do not share the edge's geometry"
                    )))
                }
                Some(_) => {}
            }
        }
    }
    let edge_nodes = edge_nodes
        .into_iter()
        .map(|n| n.map(|(p, _)| p))
        .collect::<Option<Vec<_>>>()
        .ok_or_else(|| Error::Mesh("an edge of the mesh has no middle node".into()))?;
    QuadraticGeometry::from_edge_nodes(mesh, edge_nodes)
}

/// `(dimension, physical tag, name)` of each entry of the `$PhysicalNames` section, in
/// file order; empty without the section. Gmsh writes the section as text in binary
/// files too, and `mshio` skips it, so it is read here.
///
/// # Errors
/// [`Error::Mesh`] with the line for a malformed section.
fn physical_names(bytes: &[u8]) -> Result<Vec<(usize, i32, String)>> {
    let mut lines = bytes.split(|&b| b == b'\n').enumerate();
    if !lines
        .by_ref()
        .any(|(_, l)| l.trim_ascii() == b"$PhysicalNames")
    {
        return Ok(Vec::new());
    }
    let malformed = |line: usize, why: &str| {
        Error::Mesh(format!(
            "cannot read the $PhysicalNames section at line {}: {why}",
            line + 1
        ))
    };
    let mut text = |what: &str| -> Result<(usize, String)> {
        let (i, l) = lines.next().ok_or_else(|| {
            Error::Mesh(format!(
                "cannot read the $PhysicalNames section: the file ends before {what}"
            ))
        })?;
        let l = std::str::from_utf8(l).map_err(|_| malformed(i, "the line is not UTF-8 text"))?;
        Ok((i, l.trim().to_string()))
    };
    let (at, count) = text("the number of names")?;
    let count: usize = count
        .parse()
        .map_err(|_| malformed(at, &format!("`{count}` is not a number of names")))?;
    let mut names = Vec::with_capacity(count.min(1 << 16));
    for _ in 0..count {
        let (at, line) = text("its last name")?;
        let (numbers, quoted) =
            line.split_at(line.find('"').ok_or_else(|| {
                malformed(at, &format!("`{line}` is not `dimension tag \"name\"`"))
            })?);
        let mut numbers = numbers.split_whitespace();
        let (Some(Ok(dimension)), Some(Ok(tag)), None) = (
            numbers.next().map(str::parse::<usize>),
            numbers.next().map(str::parse::<i32>),
            numbers.next(),
        ) else {
            return Err(malformed(
                at,
                &format!("`{line}` is not `dimension tag \"name\"`"),
            ));
        };
        let name = quoted
            .strip_prefix('"')
            .and_then(|q| q.strip_suffix('"'))
            .ok_or_else(|| malformed(at, &format!("the name in `{line}` is not quoted")))?;
        if dimension > 3 {
            return Err(malformed(
                at,
                &format!("dimension {dimension} is not 0 to 3"),
            ));
        }
        names.push((dimension, tag, name.to_string()));
    }
    let (at, end) = text("$EndPhysicalNames")?;
    if end != "$EndPhysicalNames" {
        return Err(malformed(
            at,
            &format!("expected $EndPhysicalNames after {count} names, found `{end}`"),
        ));
    }
    Ok(names)
}

/// What a boundary line says about its edge: one physical group of its curve, or, for
/// a curve in no physical group, the curve itself.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
enum Label {
    Group(i32),
    Curve(i32),
}

impl Label {
    fn tag(self) -> i32 {
        match self {
            Label::Group(t) | Label::Curve(t) => t,
        }
    }
}

impl std::fmt::Display for Label {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Label::Group(t) => write!(f, "physical group {t}"),
            Label::Curve(t) => write!(f, "curve {t}"),
        }
    }
}

/// The distinct label sets of the boundary edges, each with its own boundary marker, so
/// that a group is exactly the edges whose marker is one of its markers
/// ([`crate::mesh::NamedGroup`]). A set takes the tag of its first label (its lowest
/// physical group, else the curve's own tag) as Gmsh users expect to see it, unless
/// another set took it first (single groups before curves without a group before
/// combinations); then it gets a new marker above every tag in the file.
struct LabelSets(
    Vec<(Vec<Label>, u32)>,
    std::collections::HashMap<Vec<Label>, usize>,
);

impl LabelSets {
    /// Sorts each edge's labels and numbers the sets.
    ///
    /// # Errors
    /// [`Error::Mesh`] when the file's tags leave no room for a new marker (tags near
    /// 2³²).
    fn new(
        labelled: &mut [(usize, [usize; 2], Vec<Label>)],
        file: &MshFile<u64, i32, f64>,
        names: &[(usize, i32, String)],
    ) -> Result<Self> {
        let mut sets: Vec<Vec<Label>> = labelled
            .iter_mut()
            .map(|(_, _, set)| {
                set.sort_unstable();
                set.clone()
            })
            .collect();
        // singletons first (groups sort before curves), then combinations
        sets.sort_unstable_by(|a, b| (a.len(), a).cmp(&(b.len(), b)));
        sets.dedup();
        let curves = file
            .data
            .entities
            .as_ref()
            .map_or(&[][..], |e| e.curves.as_slice());
        let highest = names
            .iter()
            .map(|n| i64::from(n.1))
            .chain(curves.iter().map(|c| i64::from(c.tag)))
            .chain(
                curves
                    .iter()
                    .flat_map(|c| c.physical_tags.iter().map(|&t| i64::from(t))),
            )
            .chain(sets.iter().flatten().map(|l| i64::from(l.tag())))
            .max()
            .unwrap_or(0);
        let mut next = highest.max(0) + 1;
        let mut numbered: Vec<(Vec<Label>, u32)> = Vec::with_capacity(sets.len());
        // 0 marks the boundary edges no line lists: a group of tag 0 must not take them in
        let mut taken: std::collections::HashSet<u32> = [0].into();
        for set in sets {
            let wanted = u32::try_from(set[0].tag()).ok();
            let marker = match wanted {
                Some(m) if taken.insert(m) => m,
                _ => {
                    next += 1;
                    u32::try_from(next - 1).map_err(|_| {
                        Error::Mesh(format!(
                            "the boundary edges of {} need a marker of their own above every tag in the file, and tag {highest} leaves none",
                            set.iter().map(Label::to_string).collect::<Vec<_>>().join(" and ")
                        ))
                    })?
                }
            };
            numbered.push((set, marker));
        }
        let index = numbered
            .iter()
            .enumerate()
            .map(|(k, (set, _))| (set.clone(), k))
            .collect();
        Ok(Self(numbered, index))
    }

    /// The marker of a sorted label set from [`LabelSets::new`].
    fn marker(&self, set: &[Label]) -> u32 {
        self.1.get(set).map_or(0, |&k| self.0[k].1)
    }

    /// The markers of the sets holding each physical group, by tag.
    fn markers_of_groups(&self) -> std::collections::HashMap<i32, Vec<u32>> {
        let mut markers: std::collections::HashMap<i32, Vec<u32>> = Default::default();
        for (set, marker) in &self.0 {
            for label in set {
                if let Label::Group(tag) = label {
                    markers.entry(*tag).or_default().push(*marker);
                }
            }
        }
        for list in markers.values_mut() {
            list.sort_unstable();
            list.dedup();
        }
        markers
    }
}

/// The mesh's named groups from the `$PhysicalNames` entries: a curve group is the
/// boundary edges whose label set (`sets`) holds it, and it counts its interior edges
/// (`interior`: `(group tag, edge)`). Without `$Entities` no curve is known to be in a
/// group: the group is kept with that reason.
fn named_groups(
    file: &MshFile<u64, i32, f64>,
    names: &[(usize, i32, String)],
    sets: &LabelSets,
    interior: &std::collections::HashSet<(i32, usize)>,
) -> Vec<NamedGroup> {
    let by_group = sets.markers_of_groups();
    let mut interior_edges: std::collections::HashMap<i32, usize> = Default::default();
    for &(group, _) in interior {
        *interior_edges.entry(group).or_default() += 1;
    }
    names
        .iter()
        .map(|(dimension, tag, name)| {
            let mut group = NamedGroup {
                name: name.clone(),
                dimension: *dimension,
                markers: Vec::new(),
                interior_edges: if *dimension == 1 {
                    interior_edges.get(tag).copied().unwrap_or(0)
                } else {
                    0
                },
                ambiguity: None,
            };
            if *dimension != 1 {
                return group;
            }
            if file.data.entities.is_none() {
                group.ambiguity = Some(
                    "the file has no $Entities section, which links physical groups to their curves".into(),
                );
                return group;
            }
            let markers = by_group.get(tag).cloned().unwrap_or_default();
            group.markers = markers;
            group
        })
        .collect()
}

/// Checks the `$MeshFormat` header before `mshio` sees it, for clearer messages (and
/// because `mshio` panics on binary files with unusual integer sizes). Returns whether
/// the file is binary.
fn check_header(bytes: &[u8]) -> Result<bool> {
    let start = bytes
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .ok_or_else(|| Error::Mesh("the .msh input is empty".into()))?;
    let rest = &bytes[start..];
    if !rest.starts_with(b"$MeshFormat") {
        return Err(Error::Mesh(
            "not a Gmsh .msh file: it does not start with $MeshFormat".into(),
        ));
    }
    // the header line after $MeshFormat: version, file type, data size
    let line: Vec<&[u8]> = rest[b"$MeshFormat".len()..]
        .split(|&b| b == b'\n')
        .map(|l| l.trim_ascii())
        .find(|l| !l.is_empty())
        .unwrap_or(b"")
        .split(|b| b.is_ascii_whitespace())
        .filter(|t| !t.is_empty())
        .collect();
    let token = |i: usize| {
        line.get(i)
            .map(|t| String::from_utf8_lossy(t).into_owned())
            .unwrap_or_default()
    };
    let version = token(0);
    if version != "4.1" {
        return Err(Error::Mesh(format!(
            "MSH format version `{version}` is not supported: only version 4.1 can be read (in Gmsh, export with `-format msh41` or Mesh.MshFileVersion = 4.1)"
        )));
    }
    match (token(1).as_str(), token(2).as_str()) {
        ("0", _) => Ok(false),
        ("1", "4" | "8") => Ok(true),
        ("1", size) => Err(Error::Mesh(format!(
            "binary .msh file with data size `{size}` is not supported (only 4 or 8)"
        ))),
        (kind, _) => Err(Error::Mesh(format!(
            "invalid $MeshFormat header: file type `{kind}` must be 0 (ASCII) or 1 (binary)"
        ))),
    }
}

/// Runs `mshio`, turning its errors (and any panic inside it) into `Error::Mesh`.
fn parse_with_mshio(bytes: &[u8]) -> Result<MshFile<u64, i32, f64>> {
    match std::panic::catch_unwind(|| {
        mshio::parse_msh_bytes(bytes).map_err(|e| describe(bytes, &e))
    }) {
        Ok(Ok(file)) => Ok(file),
        Ok(Err(message)) if message.contains("arametric") => Err(Error::Mesh(format!(
            "{message}: the file stores parametric node coordinates, which can be dropped only from ASCII files; re-export it without them (in Gmsh: Mesh.SaveParametric = 0, the default)"
        ))),
        Ok(Err(message)) => Err(Error::Mesh(message)),
        Err(_) => Err(Error::Mesh(
            "the .msh parser (mshio) failed on this input; the file is probably malformed".into(),
        )),
    }
}

/// `mshio`'s error as one line with its location; its own `Display` dumps the rest of
/// the file in hex.
fn describe(bytes: &[u8], error: &mshio::MshParserError<&[u8]>) -> String {
    let filtered = error.filtered_backtrace();
    // only nom's low-level errors: report the innermost of those
    let trace = if filtered.is_empty() {
        error.backtrace.iter().take(1).cloned().collect()
    } else {
        filtered
    };
    let Some((at, kind)) = trace.first() else {
        return "cannot parse the .msh file (mshio gave no reason)".into();
    };
    let offset = (at.as_ptr() as usize)
        .checked_sub(bytes.as_ptr() as usize)
        .filter(|&o| o <= bytes.len())
        .unwrap_or(0);
    let line = bytes[..offset].iter().filter(|&&b| b == b'\n').count() + 1;
    let context: Vec<String> = trace[1..]
        .iter()
        .rev()
        .map(|(_, k)| k.context().map_or_else(|| k.to_string(), str::to_owned))
        .collect();
    let near: String = String::from_utf8_lossy(&bytes[offset..bytes.len().min(offset + 40)])
        .lines()
        .next()
        .unwrap_or("")
        .chars()
        .filter(|c| !c.is_control())
        .collect();
    let reason = if kind.is_nom_error() {
        format!("unexpected `{near}`")
    } else {
        format!("{kind} (near `{near}`)")
    };
    let mut message =
        format!("cannot parse the .msh file at line {line} (byte {offset}): {reason}");
    if !context.is_empty() {
        message.push_str(&format!(" (in {})", context.join(" › ")));
    }
    message
}

/// Node coordinates by tag, sorted for binary search.
struct NodeTable(Vec<(u64, [f64; 3])>);

impl NodeTable {
    fn get(&self, tag: u64) -> Option<[f64; 3]> {
        self.0
            .binary_search_by_key(&tag, |n| n.0)
            .ok()
            .map(|i| self.0[i].1)
    }
}

/// The node table. `mshio` keeps node tags only when they are sparse, and otherwise
/// assumes they run consecutively in file order; for ASCII files the tags read from the
/// text (`ascii_tags`) are used instead, so out-of-order files are read correctly.
fn node_table(file: &MshFile<u64, i32, f64>, ascii_tags: Option<Vec<u64>>) -> Result<NodeTable> {
    let Some(nodes) = &file.data.nodes else {
        return Err(Error::Mesh("the .msh file has no $Nodes section".into()));
    };
    let total: usize = nodes.node_blocks.iter().map(|b| b.nodes.len()).sum();
    let ascii_tags = ascii_tags.filter(|t| t.len() == total);
    let mut table = Vec::with_capacity(total);
    let mut running = 0usize;
    for block in &nodes.node_blocks {
        let mut tags = vec![0u64; block.nodes.len()];
        if let Some(all) = &ascii_tags {
            tags.copy_from_slice(&all[running..running + block.nodes.len()]);
        } else if let Some(map) = &block.node_tags {
            for (&tag, &i) in map {
                if let Some(slot) = tags.get_mut(i) {
                    *slot = tag;
                }
            }
        } else {
            for (i, tag) in tags.iter_mut().enumerate() {
                *tag = nodes.min_node_tag + (running + i) as u64;
            }
        }
        for (node, tag) in block.nodes.iter().zip(tags) {
            table.push((tag, [node.x, node.y, node.z]));
        }
        running += block.nodes.len();
    }
    table.sort_unstable_by_key(|n| n.0);
    if let Some(w) = table.windows(2).find(|w| w[0].0 == w[1].0) {
        return Err(Error::Mesh(format!("node {} is defined twice", w[0].0)));
    }
    Ok(NodeTable(table))
}

/// The node tags of an ASCII file's `$Nodes` section in file order, or `None` if the
/// section cannot be walked (then `mshio`'s numbering is used).
fn ascii_node_tags(bytes: &[u8]) -> Option<Vec<u64>> {
    let text = std::str::from_utf8(bytes).ok()?;
    let mut offset = 0;
    let mut start = None;
    for line in text.split_inclusive('\n') {
        offset += line.len();
        if line.trim() == "$Nodes" {
            start = Some(offset);
            break;
        }
    }
    let body = &text[start?..];
    let body = &body[..body.find("$EndNodes")?];
    let mut tokens = body.split_ascii_whitespace();
    fn int(tokens: &mut std::str::SplitAsciiWhitespace) -> Option<u64> {
        tokens.next()?.parse::<u64>().ok()
    }
    let blocks = int(&mut tokens)?;
    let (_count, _min, _max) = (int(&mut tokens)?, int(&mut tokens)?, int(&mut tokens)?);
    let mut tags = Vec::new();
    for _ in 0..blocks {
        let (_dim, _entity, parametric, n) = (
            int(&mut tokens)?,
            int(&mut tokens)?,
            int(&mut tokens)?,
            int(&mut tokens)?,
        );
        if parametric != 0 {
            return None;
        }
        for _ in 0..n {
            tags.push(int(&mut tokens)?);
        }
        // the coordinates are floats: skip them by position
        for _ in 0..3 * n {
            tokens.next()?;
        }
    }
    Some(tags)
}

/// The ASCII file with its parametric node coordinates dropped, or `None` if it has
/// none (or its `$Nodes` section cannot be walked; `mshio` then reports the fault).
///
/// In MSH 4.1 a node block with `parametric = 1` on an entity of dimension `d` gives
/// each node `d` parametric coordinates after `x y z` (Gmsh writes them with
/// `Mesh.SaveParametric = 1`); `mshio` does not read them. They are not needed for a
/// planar triangle mesh, so the block is rewritten with `parametric = 0`, one node per
/// line as Gmsh writes it, keeping the line numbers of a Gmsh-written file.
fn strip_parametric(bytes: &[u8]) -> Option<Vec<u8>> {
    let text = std::str::from_utf8(bytes).ok()?;
    let mut offset = 0;
    let mut start = None;
    for line in text.split_inclusive('\n') {
        offset += line.len();
        if line.trim() == "$Nodes" {
            start = Some(offset);
            break;
        }
    }
    let start = start?;
    let end = start + text[start..].find("$EndNodes")?;
    let mut tokens = text[start..end].split_ascii_whitespace();
    let header: Vec<&str> = (0..4).map(|_| tokens.next()).collect::<Option<_>>()?;
    let blocks: usize = header[0].parse().ok()?;
    let mut out = format!("{}\n", header.join(" "));
    let mut any = false;
    for _ in 0..blocks {
        let block: Vec<&str> = (0..4).map(|_| tokens.next()).collect::<Option<_>>()?;
        let dim: usize = block[0].parse().ok()?;
        let parametric = match block[2] {
            "0" => false,
            "1" => true,
            _ => return None,
        };
        let n: usize = block[3].parse().ok()?;
        any |= parametric;
        out.push_str(&format!("{} {} 0 {n}\n", block[0], block[1]));
        for _ in 0..n {
            out.push_str(tokens.next()?);
            out.push('\n');
        }
        let extra = if parametric { dim.min(3) } else { 0 };
        for _ in 0..n {
            let xyz: Vec<&str> = (0..3).map(|_| tokens.next()).collect::<Option<_>>()?;
            for _ in 0..extra {
                tokens.next()?;
            }
            out.push_str(&xyz.join(" "));
            out.push('\n');
        }
    }
    if !any || tokens.next().is_some() {
        return None;
    }
    let mut rewritten = Vec::with_capacity(bytes.len());
    rewritten.extend_from_slice(&bytes[..start]);
    rewritten.extend_from_slice(out.as_bytes());
    rewritten.extend_from_slice(&bytes[end..]);
    Some(rewritten)
}

/// The elements the mesh is made of, with their Gmsh element tags.
struct Elements {
    /// (element tag, node tags of the corners)
    triangles: Vec<(u64, [u64; 3])>,
    /// For 6-node triangles, in the order of `triangles`: (element tag, node tags of the
    /// middles of edges 0–1, 1–2, 2–0); empty for 3-node triangles.
    edge_nodes: Vec<(u64, [u64; 3])>,
    /// (element tag, node tags, curve's entity tag)
    lines: Vec<(u64, [u64; 2], i32)>,
}

fn type_name(t: ElementType) -> String {
    format!("{t:?} (Gmsh type {})", t as i32)
}

fn collect_elements(file: &MshFile<u64, i32, f64>, quadratic: bool) -> Result<Elements> {
    let Some(elements) = &file.data.elements else {
        return Err(Error::Mesh(
            "the .msh file has no $Elements section, so no triangles".into(),
        ));
    };
    let mut found: Vec<(ElementType, usize)> = Vec::new();
    let mut triangles = Vec::new();
    let mut edge_nodes = Vec::new();
    let mut lines = Vec::new();
    for block in &elements.element_blocks {
        match found.iter_mut().find(|(t, _)| *t == block.element_type) {
            Some((_, n)) => *n += block.elements.len(),
            None => found.push((block.element_type, block.elements.len())),
        }
        match block.element_type {
            ElementType::Tri3 if !quadratic => {
                for e in &block.elements {
                    triangles.push((e.element_tag, [e.nodes[0], e.nodes[1], e.nodes[2]]));
                }
            }
            ElementType::Tri6 if quadratic => {
                for e in &block.elements {
                    triangles.push((e.element_tag, [e.nodes[0], e.nodes[1], e.nodes[2]]));
                    edge_nodes.push((e.element_tag, [e.nodes[3], e.nodes[4], e.nodes[5]]));
                }
            }
            ElementType::Lin2 | ElementType::Lin3
                if (block.element_type == ElementType::Lin3) == quadratic =>
            {
                // the groups of a line are its curve's: a line block filed under a point
                // or a surface would take the groups of the curve of the same tag
                if block.entity_dim != 1 {
                    let first = block.elements.first().map_or(0, |e| e.element_tag);
                    return Err(Error::Mesh(format!(
                        "the block of line elements from element {first} belongs to an entity of dimension {} (tag {}), not to a curve (dimension 1): its lines cannot be given the curve's physical groups; write each line block under its curve",
                        block.entity_dim, block.entity_tag
                    )));
                }
                for e in &block.elements {
                    lines.push((e.element_tag, [e.nodes[0], e.nodes[1]], block.entity_tag));
                }
            }
            _ => {}
        }
    }
    let list = |types: &[(ElementType, usize)]| {
        types
            .iter()
            .map(|&(t, n)| format!("{} ×{n}", type_name(t)))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let (triangle, line) = if quadratic {
        (ElementType::Tri6, ElementType::Lin3)
    } else {
        (ElementType::Tri3, ElementType::Lin2)
    };
    let of_the_other_order: Vec<(ElementType, usize)> = found
        .iter()
        .copied()
        .filter(|&(t, _)| {
            let name = format!("{t:?}");
            (name.starts_with("Tri") || name.starts_with("Lin")) && t != triangle && t != line
        })
        .collect();
    if !of_the_other_order.is_empty() {
        return Err(Error::Mesh(if quadratic {
            format!(
                "a quadratic geometry is read from 6-node triangles with 3-node boundary lines only (found {}): mesh with Mesh.ElementOrder = 2",
                list(&of_the_other_order)
            )
        } else {
            format!(
                "second- or higher-order elements are not supported here (found {}); only 3-node triangles can be read as a mesh of straight cells: mesh with Mesh.ElementOrder = 1 (6-node triangles are read as a curved geometry by the library's `read_msh_quadratic`, for the curved-cell solvers; the membrane command line takes straight cells only)",
                list(&of_the_other_order)
            )
        }));
    }
    if triangles.is_empty() {
        let kind = if quadratic { "6-node" } else { "3-node" };
        let found = if found.is_empty() {
            "none".to_string()
        } else {
            list(&found)
        };
        return Err(Error::Mesh(format!(
            "the .msh file has no {kind} triangles (element types found: {found}); only {kind} triangles ({}) are supported",
            type_name(triangle)
        )));
    }
    let other: Vec<(ElementType, usize)> = found
        .iter()
        .copied()
        .filter(|&(t, _)| t != triangle && t != line && t != ElementType::Pnt)
        .collect();
    if !other.is_empty() {
        return Err(Error::Mesh(format!(
            "unsupported element types {}: only {} (with boundary lines and points) can be read",
            list(&other),
            type_name(triangle)
        )));
    }
    Ok(Elements {
        triangles,
        edge_nodes,
        lines,
    })
}

/// All coordinates must have `z = 0` up to 1e-12 of the extent in the plane.
fn check_planar(vertices: &[[f64; 2]], zs: &[f64], tags: &[u64]) -> Result<()> {
    let mut lower = [f64::INFINITY; 2];
    let mut upper = [f64::NEG_INFINITY; 2];
    for v in vertices {
        for d in 0..2 {
            lower[d] = lower[d].min(v[d]);
            upper[d] = upper[d].max(v[d]);
        }
    }
    let extent = (upper[0] - lower[0]).max(upper[1] - lower[1]);
    for (i, &z) in zs.iter().enumerate() {
        let planar = z == 0.0 || z.abs() <= 1e-12 * extent;
        if !planar {
            return Err(Error::Mesh(format!(
                "node {} has z = {z}: only meshes in the plane z = 0 are supported",
                tags[i]
            )));
        }
    }
    Ok(())
}

/// Makes every triangle counter-clockwise by itself, swapping its last two nodes when it
/// is clockwise, and returns how many were swapped.
///
/// Gmsh writes each surface's triangles in the orientation of the surface's normal, so
/// a valid planar mesh may mix orientations (two surfaces with opposite normals, as
/// after boolean operations or a reversed curve loop). Orientation is therefore no
/// evidence of a fault; folded or overlapping cells are caught by
/// [`TriangleMesh::new`] (two cells on the same side of an edge), and cells of (near)
/// zero area are refused there too. Boundary lines are matched to edges whatever their
/// node order, so swapping keeps the markers.
fn orient(vertices: &[[f64; 2]], cells: &mut [[usize; 3]]) -> usize {
    let mut swapped = 0;
    for c in cells.iter_mut() {
        let Some((p, q, r)) = c
            .iter()
            .map(|&v| vertices.get(v).copied())
            .collect::<Option<Vec<_>>>()
            .map(|x| (x[0], x[1], x[2]))
        else {
            continue;
        };
        let twice_area = (q[0] - p[0]) * (r[1] - p[1]) - (r[0] - p[0]) * (q[1] - p[1]);
        if twice_area < 0.0 {
            c.swap(1, 2);
            swapped += 1;
        }
    }
    swapped
}

/// Refuses a mesh with coincident vertices ([`TriangleMesh::coincident_vertices`]),
/// naming them and their coordinates and saying how to fix the mesh in Gmsh.
///
/// Merging them instead would silently change the user's model (the two copies may also
/// be the lips of an intended slit), so the fix is left to the mesh's author. Without
/// coincident vertices, hanging ones are looked for ([`refuse_hanging_vertices`]).
fn refuse_duplicate_nodes(mesh: &TriangleMesh) -> Result<()> {
    let pairs = mesh.coincident_vertices();
    let Some(&[a, b]) = pairs.first() else {
        return refuse_hanging_vertices(mesh);
    };
    let [x, y] = mesh.vertices()[a];
    let more = match pairs.len() {
        1 => String::new(),
        n => format!(" ({n} such pairs in all)"),
    };
    Err(Error::Mesh(format!(
        "vertex {a} and vertex {b} coincide at ({x}, {y}){more}: the mesh has duplicate nodes, as when two surfaces are meshed separately along a common curve, and would be solved with a cut (a boundary where u = g) inside the domain; in Gmsh, make the geometry coherent before meshing (`Coherence;` in a built-in-kernel .geo script, Geometry.AutoCoherence = 1, or BooleanFragments with OpenCASCADE) or merge the mesh's duplicates with `Coherence Mesh;`, then re-export"
    )))
}

/// Refuses a mesh with a boundary vertex inside another boundary edge
/// ([`TriangleMesh::vertices_on_boundary_edges`]): a curve meshed separately, with
/// different nodes, by the two surfaces it separates.
fn refuse_hanging_vertices(mesh: &TriangleMesh) -> Result<()> {
    let found = mesh.vertices_on_boundary_edges();
    let Some(&(v, e)) = found.first() else {
        return Ok(());
    };
    let [x, y] = mesh.vertices()[v];
    let [a, b] = mesh.edges()[e];
    let more = match found.len() {
        1 => String::new(),
        n => format!(" ({n} such vertices in all)"),
    };
    Err(Error::Mesh(format!(
        "vertex {v} at ({x}, {y}) lies on the boundary edge from vertex {a} to vertex {b} without being one of its ends{more}: the mesh has boundary edges inside the domain, as when two surfaces are meshed separately along a common curve, and would be solved with a cut (a boundary where u = g) there; in Gmsh, make the geometry coherent before meshing (`Coherence;` in a built-in-kernel .geo script, Geometry.AutoCoherence = 1, or BooleanFragments with OpenCASCADE), then re-mesh and re-export"
    )))
}

/// Adds Gmsh's numbers to a mesh message: "cell 3" → "cell 3 (element 17)",
/// "vertex 5" → "vertex 5 (node 12)".
fn annotate_indices(message: &str, element_of_cell: &[u64], node_of_vertex: &[u64]) -> String {
    let mut out = String::with_capacity(message.len() + 32);
    let mut rest = message;
    while !rest.is_empty() {
        let found = [
            ("cell ", element_of_cell, "element"),
            ("vertex ", node_of_vertex, "node"),
        ]
        .into_iter()
        .filter_map(|(word, table, name)| rest.find(word).map(|at| (at, word, table, name)))
        .min_by_key(|f| f.0);
        let Some((at, word, table, name)) = found else {
            out.push_str(rest);
            break;
        };
        let after = &rest[at + word.len()..];
        let digits = after.len() - after.trim_start_matches(|c: char| c.is_ascii_digit()).len();
        out.push_str(&rest[..at + word.len() + digits]);
        if let Some(tag) = after[..digits]
            .parse::<usize>()
            .ok()
            .and_then(|i| table.get(i))
        {
            out.push_str(&format!(" ({name} {tag})"));
        }
        rest = &after[digits..];
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit square from two triangles, with boundary lines on four curves: curves 1
    /// and 2 are in physical groups 10 and 20, curves 3 and 4 in none. Node 10 is a
    /// geometry point no triangle uses; node tags are sparse (1–4, 10).
    const SQUARE: &str = "$MeshFormat
4.1 0 8
$EndMeshFormat
$Entities
5 4 1 0
1 0 0 0 0
2 1 0 0 0
3 1 1 0 0
4 0 1 0 0
5 2 2 0 0
1 0 0 0 1 0 0 1 10 2 1 -2
2 1 0 0 1 1 0 1 20 2 2 -3
3 0 1 0 1 1 0 0 2 3 -4
4 0 0 0 0 1 0 0 2 4 -1
1 0 0 0 1 1 0 1 100 4 1 2 3 4
$EndEntities
$Nodes
5 5 1 10
0 1 0 1
1
0 0 0
0 2 0 1
2
1 0 0
0 3 0 1
3
1 1 0
0 4 0 1
4
0 1 0
0 5 0 1
10
2 2 0
$EndNodes
$Elements
7 8 1 8
1 1 1 1
1 1 2
1 2 1 1
2 2 3
1 3 1 1
3 3 4
1 4 1 1
4 4 1
2 1 2 2
5 1 2 3
6 1 3 4
0 1 15 1
7 1
0 5 15 1
8 10
$EndElements
";

    fn marker_of(m: &TriangleMesh, p: [f64; 2], q: [f64; 2]) -> u32 {
        let find = |x: [f64; 2]| m.vertices().iter().position(|&v| v == x).unwrap();
        let e = m.find_edge(find(p), find(q)).unwrap();
        m.boundary_edges().iter().find(|b| b.0 == e).unwrap().1
    }

    fn error(text: &str) -> String {
        match parse_msh(text.as_bytes()) {
            Ok(_) => panic!("the file was accepted"),
            Err(Error::Mesh(m)) => m,
            Err(e) => panic!("not a mesh error: {e}"),
        }
    }

    #[test]
    fn reads_the_unit_square() {
        let m = parse_msh(SQUARE.as_bytes()).unwrap();
        assert_eq!(m.vertex_count(), 4, "node 10 is dropped");
        assert_eq!(m.cell_count(), 2);
        assert_eq!(
            m.vertices(),
            &[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
        );
        assert!((0..2).all(|c| m.area(c) > 0.0));
        assert_eq!(marker_of(&m, [0.0, 0.0], [1.0, 0.0]), 10);
        assert_eq!(marker_of(&m, [1.0, 0.0], [1.0, 1.0]), 20);
        assert_eq!(marker_of(&m, [1.0, 1.0], [0.0, 1.0]), 3);
        assert_eq!(marker_of(&m, [0.0, 1.0], [0.0, 0.0]), 4);
    }

    #[test]
    fn reads_dense_tags_out_of_order_and_clockwise_triangles() {
        // one node block with tags 1–4 listed out of order, clockwise triangles, and no
        // $Entities section (markers are the curves' entity tags)
        let text = "$MeshFormat
4.1 0 8
$EndMeshFormat
$Nodes
1 4 1 4
2 1 0 4
3
1
4
2
1 1 0
0 0 0
0 1 0
1 0 0
$EndNodes
$Elements
2 3 1 3
1 7 1 1
1 1 2
2 1 2 2
2 1 3 2
3 1 4 3
$EndElements
";
        let m = parse_msh(text.as_bytes()).unwrap();
        assert_eq!(
            m.vertices(),
            &[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
        );
        assert!((0..2).all(|c| m.area(c) > 0.0));
        assert!(((0..2).map(|c| m.area(c)).sum::<f64>() - 1.0).abs() < 1e-15);
        assert_eq!(marker_of(&m, [0.0, 0.0], [1.0, 0.0]), 7);
        assert_eq!(marker_of(&m, [1.0, 0.0], [1.0, 1.0]), 0);
    }

    #[test]
    fn reads_binary_files() {
        // the unit square in binary MSH 4.1 (little endian, 8-byte size_t), no $Entities
        let mut b: Vec<u8> = b"$MeshFormat\n4.1 1 8\n".to_vec();
        b.extend(1i32.to_le_bytes());
        b.extend(b"\n$EndMeshFormat\n$PhysicalNames\n1\n1 5 \"base\"\n$EndPhysicalNames\n$Nodes\n");
        let size = |b: &mut Vec<u8>, x: u64| b.extend(x.to_le_bytes());
        let int = |b: &mut Vec<u8>, x: i32| b.extend(x.to_le_bytes());
        for x in [1, 4, 1, 4] {
            size(&mut b, x);
        }
        for x in [2, 1, 0] {
            int(&mut b, x);
        }
        size(&mut b, 4);
        for tag in 1..=4 {
            size(&mut b, tag);
        }
        for x in [
            0.0f64, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0,
        ] {
            b.extend(x.to_le_bytes());
        }
        b.extend(b"\n$EndNodes\n$Elements\n");
        for x in [2, 3, 1, 3] {
            size(&mut b, x);
        }
        for x in [1, 5, 1] {
            int(&mut b, x);
        }
        size(&mut b, 1);
        for x in [1, 1, 2] {
            size(&mut b, x);
        }
        for x in [2, 1, 2] {
            int(&mut b, x);
        }
        size(&mut b, 2);
        for x in [2, 1, 2, 3, 3, 1, 3, 4] {
            size(&mut b, x);
        }
        b.extend(b"\n$EndElements\n");
        let m = parse_msh(&b).unwrap();
        assert_eq!(
            m.vertices(),
            &[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
        );
        assert_eq!(m.cell_count(), 2);
        assert_eq!(marker_of(&m, [0.0, 0.0], [1.0, 0.0]), 5);
        // the names are text in binary files too; without $Entities no curve is known
        // to be in the group
        assert_eq!(m.boundary_part_names(), ["base"]);
        let e = m.boundary_part_markers(&["base"]).unwrap_err().to_string();
        assert!(e.contains("$Entities"), "{e}");
        // a binary header with an integer size mshio cannot read is an error, not a panic
        let mut odd = b.clone();
        odd[18] = b'3';
        assert!(error(std::str::from_utf8(&odd[..20]).unwrap()).contains("data size"));
    }

    #[test]
    fn mixed_orientations_are_oriented_cell_by_cell() {
        // element 6 clockwise, element 5 counter-clockwise: two surfaces of opposite normals
        let mixed = parse_msh(SQUARE.replace("6 1 3 4", "6 1 4 3").as_bytes()).unwrap();
        let square = parse_msh(SQUARE.as_bytes()).unwrap();
        assert!((0..2).all(|c| mixed.area(c) > 0.0));
        let sets = |m: &TriangleMesh| {
            let mut cells: Vec<[usize; 3]> = m
                .cells()
                .iter()
                .map(|c| {
                    let mut c = *c;
                    c.sort_unstable();
                    c
                })
                .collect();
            cells.sort_unstable();
            cells
        };
        assert_eq!(sets(&mixed), sets(&square));
        assert_eq!(mixed.boundary_edges(), square.boundary_edges());
        // a fold (two cells on the same side of their common edge) is still refused
        let folded = SQUARE
            .replace("6 1 3 4", "6 1 3 10")
            .replace("10\n2 2 0", "10\n2 0.5 0");
        let e = error(&folded);
        assert!(e.contains("overlap") && e.contains("element 5"), "{e}");
        // and so is a flat cell, whatever its orientation
        let flat = SQUARE.replace("0 4 0 1\n4\n0 1 0", "0 4 0 1\n4\n2 2 0");
        let e = error(&flat);
        assert!(e.contains("degenerate") && e.contains("element 6"), "{e}");
    }

    #[test]
    fn parametric_coordinates_are_dropped() {
        // SQUARE with the corner nodes written with parametric coordinates: none on
        // points (dimension 0), u on a curve, u v on a surface
        let text = SQUARE
            .replace("0 1 0 1\n1\n0 0 0", "0 1 1 1\n1\n0 0 0")
            .replace("0 2 0 1\n2\n1 0 0", "1 1 1 1\n2\n1 0 0 0.5")
            .replace("0 3 0 1\n3\n1 1 0", "2 1 1 1\n3\n1 1 0 0.25 0.75");
        let m = parse_msh(text.as_bytes()).unwrap();
        assert_eq!(m, parse_msh(SQUARE.as_bytes()).unwrap());
        // a malformed parametric block reaches mshio, whose refusal gets the fix
        let broken = text.replace("1 1 0 0.25 0.75", "1 1 0 0.25");
        let e = error(&broken);
        assert!(e.contains("SaveParametric"), "{e}");
    }

    #[test]
    fn duplicate_nodes_are_refused_with_their_place_and_the_fix() {
        // the square as two triangles that do not share their diagonal: nodes 5 and 6
        // duplicate nodes 1 and 3
        let text = SQUARE
            .replace("5 5 1 10", "6 7 1 10")
            .replace(
                "0 5 0 1\n10\n2 2 0",
                "0 5 0 1\n10\n2 2 0\n2 1 0 2\n5\n6\n0 0 0\n1 1 0",
            )
            .replace("6 1 3 4", "6 5 6 4");
        let e = error(&text);
        assert!(
            e.contains("node 1")
                && e.contains("node 5")
                && e.contains("(0, 0)")
                && e.contains("2 such pairs")
                && e.contains("Coherence"),
            "{e}"
        );
    }

    #[test]
    fn rejects_bad_files() {
        assert!(error("").contains("empty"));
        assert!(error("hello world\n").contains("$MeshFormat"));
        let e = error("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n");
        assert!(e.contains("2.2") && e.contains("4.1"), "{e}");
        let e = error(&SQUARE.replace("1 0 0 0 1 0 0 1 10 2 1 -2", "1 0 0 zero"));
        assert!(e.contains("cannot parse") && e.contains("line"), "{e}");
        // cut inside the $Nodes section, and after $EndEntities
        let e = error(&SQUARE[..SQUARE.find("$EndNodes").unwrap() - 5]);
        assert!(e.contains("cannot parse"), "{e}");
        let e = error(&SQUARE[..SQUARE.find("$Nodes").unwrap()]);
        assert!(e.contains("no $Nodes"), "{e}");
        let e = error(&SQUARE[..SQUARE.find("$Elements").unwrap()]);
        assert!(e.contains("no $Elements"), "{e}");
        let e = error(&SQUARE.replace("5 1 2 3", "5 1 2 33"));
        assert!(e.contains("element 5") && e.contains("node 33"), "{e}");
        let e = error(&SQUARE.replace("1 1 0\n0 4", "1 1 0.5\n0 4"));
        assert!(e.contains("node 3") && e.contains("z = 0.5"), "{e}");
    }

    #[test]
    fn rejects_quads_and_second_order() {
        let quads = "$MeshFormat
4.1 0 8
$EndMeshFormat
$Nodes
1 4 1 4
2 1 0 4
1
2
3
4
0 0 0
1 0 0
1 1 0
0 1 0
$EndNodes
$Elements
1 1 1 1
2 1 3 1
1 1 2 3 4
$EndElements
";
        let e = error(quads);
        assert!(
            e.contains("Qua4") && e.contains("no 3-node triangles"),
            "{e}"
        );
        let tri6 = "$MeshFormat
4.1 0 8
$EndMeshFormat
$Nodes
1 6 1 6
2 1 0 6
1
2
3
4
5
6
0 0 0
1 0 0
0 1 0
0.5 0 0
0.5 0.5 0
0 0.5 0
$EndNodes
$Elements
1 1 1 1
2 1 9 1
1 1 2 3 4 5 6
$EndElements
";
        let e = error(tri6);
        assert!(e.contains("Tri6") && e.contains("not supported"), "{e}");
        let mixed = SQUARE.replace("7 8 1 8", "8 8 1 8").replace(
            "2 1 2 2\n5 1 2 3\n6 1 3 4",
            "2 1 2 1\n5 1 2 3\n2 1 3 1\n6 1 3 4 10",
        );
        let e = error(&mixed);
        assert!(e.contains("Qua4") && e.contains("unsupported"), "{e}");
    }

    #[test]
    fn mesh_errors_name_gmsh_elements() {
        // a duplicate triangle: the message gives the Gmsh element tags too
        let text = SQUARE.replace("7 8 1 8", "7 9 1 9").replace(
            "2 1 2 2\n5 1 2 3\n6 1 3 4",
            "2 1 2 3\n5 1 2 3\n6 1 3 4\n9 2 3 1",
        );
        let e = error(&text);
        assert!(
            e.contains("element 5") && e.contains("element 9") && e.contains("duplicates"),
            "{e}"
        );
    }

    #[test]
    fn hanging_vertices_on_an_inner_boundary_are_refused() {
        // the upper-left half split at node 10 = (0.5, 0.5), the lower-right half not:
        // node 10 hangs on the diagonal, a boundary edge inside the square
        let text = SQUARE
            .replace("7 8 1 8", "7 9 1 9")
            .replace(
                "2 1 2 2\n5 1 2 3\n6 1 3 4",
                "2 1 2 3\n5 1 2 3\n6 1 10 4\n9 10 3 4",
            )
            .replace("10\n2 2 0", "10\n0.5 0.5 0");
        let e = error(&text);
        assert!(
            e.contains("node 10")
                && e.contains("(0.5, 0.5)")
                && e.contains("vertex 0 (node 1) to vertex 2 (node 3)")
                && e.contains("Coherence"),
            "{e}"
        );
    }

    /// SQUARE with a `$PhysicalNames` section: curve groups 10 and 20, the surface
    /// group 100, and a curve group 30 that no curve is in.
    fn named_square() -> String {
        SQUARE.replace(
            "$EndMeshFormat\n",
            "$EndMeshFormat\n$PhysicalNames\n4\n1 10 \"bottom\"\n1 20 \"right side\"\n2 100 \"plate\"\n1 30 \"nowhere\"\n$EndPhysicalNames\n",
        )
    }

    #[test]
    fn physical_names_name_boundary_parts() {
        let m = parse_msh(named_square().as_bytes()).unwrap();
        assert_eq!(m.boundary_part_names(), ["bottom", "right side", "nowhere"]);
        assert_eq!(m.boundary_part_markers(&["bottom"]).unwrap(), [10]);
        assert_eq!(
            m.boundary_part_markers(&["right side", "bottom"]).unwrap(),
            [10, 20]
        );
        // the bottom edge, marker 10, is the part `bottom`
        assert_eq!(marker_of(&m, [0.0, 0.0], [1.0, 0.0]), 10);
        assert_eq!(m.boundary_edges_with_markers(&[10]), 1);
        // a group without curves has no markers: it selects no edge
        assert_eq!(
            m.boundary_part_markers(&["nowhere"]).unwrap(),
            Vec::<u32>::new()
        );
        let e = m.boundary_part_markers(&["plate"]).unwrap_err().to_string();
        assert!(e.contains("`plate`") && e.contains("surface"), "{e}");
        let e = m.boundary_part_markers(&["left"]).unwrap_err().to_string();
        assert!(
            e.contains("`left`") && e.contains("`bottom`") && e.contains("`right side`"),
            "{e}"
        );
        // curve 4 has no group: its marker is its entity tag, which has no name
        let e = m.boundary_part_markers(&["4"]).unwrap_err().to_string();
        assert!(
            e.contains("not by tag or marker")
                && e.contains("marker 4 exist, but no name")
                && e.contains("Physical Curve"),
            "{e}"
        );
        // a physical tag that has a name: the message names it
        let e = m.boundary_part_markers(&["20"]).unwrap_err().to_string();
        assert!(e.contains("marker 20 belong to `right side`"), "{e}");
        // the names stay through refinement
        let fine = m.refine_uniformly();
        assert_eq!(fine.boundary_part_markers(&["bottom"]).unwrap(), [10]);
        assert_eq!(fine.boundary_edges_with_markers(&[10]), 2);
        // a file without the section names nothing
        assert!(parse_msh(SQUARE.as_bytes())
            .unwrap()
            .named_groups()
            .is_empty());
    }

    /// Curve 3 in group 4 and curve 4 in no group both wanted marker 4 (a group's tag,
    /// a curve's own tag); they used to share it, and `top` could not be chosen. Each
    /// kind of edge has its own marker now, and `top` is the top edge alone.
    #[test]
    fn a_group_and_a_curve_of_the_same_tag_get_their_own_markers() {
        let text = named_square()
            .replace("3 0 1 0 1 1 0 0 2 3 -4", "3 0 1 0 1 1 0 1 4 2 3 -4")
            .replace("4\n1 10 \"bottom\"", "5\n1 4 \"top\"\n1 10 \"bottom\"");
        let m = parse_msh(text.as_bytes()).unwrap();
        let top = m.boundary_part_markers(&["top"]).unwrap();
        assert_eq!(top, [4]);
        assert_eq!(marker_of(&m, [1.0, 1.0], [0.0, 1.0]), 4);
        assert_eq!(m.boundary_edges_with_markers(&top), 1);
        assert_ne!(marker_of(&m, [0.0, 1.0], [0.0, 0.0]), 4);
        // the other groups are unaffected
        assert_eq!(m.boundary_part_markers(&["bottom"]).unwrap(), [10]);
    }

    /// A group of physical tag 0: boundary edges no line lists are marked 0, and
    /// the group took them in (its membrane was held on a side it did not name). The
    /// group gets a marker of its own.
    #[test]
    fn a_group_of_tag_zero_does_not_take_the_unlisted_edges() {
        // curve 4 (the left side) in group 0, curve 2's line (the right side) removed
        let text = named_square()
            .replace("4 0 0 0 0 1 0 0 2 4 -1", "4 0 0 0 0 1 0 1 0 2 4 -1")
            .replace("4\n1 10 \"bottom\"", "5\n1 0 \"left\"\n1 10 \"bottom\"")
            .replace("7 8 1 8\n", "6 7 1 8\n")
            .replace("1 2 1 1\n2 2 3\n", "");
        let m = parse_msh(text.as_bytes()).unwrap();
        let left = m.boundary_part_markers(&["left"]).unwrap();
        assert_eq!(m.boundary_edges_with_markers(&left), 1);
        assert_eq!(left, [marker_of(&m, [0.0, 1.0], [0.0, 0.0])]);
        assert_eq!(marker_of(&m, [1.0, 0.0], [1.0, 1.0]), 0);
        assert!(!left.contains(&0));
    }

    /// Lines filed under a surface (or point) would take the groups of the curve of the
    /// same tag: refused, naming the block. A curve listed twice in `$Entities` has
    /// ambiguous groups: refused, naming the curve.
    #[test]
    fn lines_outside_curves_and_curves_listed_twice_are_refused() {
        let e = error(&SQUARE.replace("1 1 1 1\n1 1 2\n", "2 1 1 1\n1 1 2\n"));
        assert!(
            e.contains("element 1") && e.contains("dimension 2") && e.contains("not to a curve"),
            "{e}"
        );
        let twice = SQUARE.replace("5 4 1 0\n", "5 5 1 0\n").replace(
            "4 0 0 0 0 1 0 0 2 4 -1\n",
            "4 0 0 0 0 1 0 0 2 4 -1\n4 0 0 0 0 1 0 1 30 2 4 -1\n",
        );
        let e = error(&twice);
        assert!(e.contains("curve 4 is listed twice"), "{e}");
    }

    /// Lines on interior edges (an embedded curve) give no marker, but their groups count
    /// them, so that a boundary part with an interior wire is warned about.
    #[test]
    fn groups_count_their_interior_edges() {
        // curve 3 (the top) in the group `wire`, with a second line on the diagonal from
        // node 1 to node 3, the edge the two triangles share
        let text = named_square()
            .replace("3 0 1 0 1 1 0 0 2 3 -4", "3 0 1 0 1 1 0 1 30 2 3 -4")
            .replace("4\n1 10 \"bottom\"", "5\n1 30 \"wire\"\n1 10 \"bottom\"")
            .replace("7 8 1 8\n", "7 9 1 9\n")
            .replace("1 3 1 1\n3 3 4\n", "1 3 1 2\n3 3 4\n9 1 3\n");
        let m = parse_msh(text.as_bytes()).unwrap();
        assert_eq!(
            m.interior_edges_of(&["wire", "bottom"]),
            [("wire".to_string(), 1)]
        );
        assert_eq!(
            m.boundary_edges_with_markers(&m.boundary_part_markers(&["wire"]).unwrap()),
            1
        );
    }

    #[test]
    fn malformed_physical_names_are_errors_with_their_line() {
        let e = error(&named_square().replace("\"bottom\"", "bottom"));
        assert!(e.contains("$PhysicalNames") && e.contains("line 6"), "{e}");
        let e = error(&named_square().replace("1 10 \"bottom\"", "x 10 \"bottom\""));
        assert!(e.contains("line 6") && e.contains("dimension tag"), "{e}");
        let e = error(&named_square().replace("\n4\n1 10", "\n5\n1 10"));
        assert!(e.contains("$EndPhysicalNames"), "{e}");
        let e = error(&named_square().replace("\n4\n1 10", "\nmany\n1 10"));
        assert!(e.contains("line 5") && e.contains("many"), "{e}");
    }

    #[test]
    fn read_msh_reads_files_and_reports_missing_ones() {
        let dir = std::env::temp_dir().join(format!("fem-gmsh-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("square.msh");
        std::fs::write(&path, SQUARE).unwrap();
        assert_eq!(read_msh(&path).unwrap().cell_count(), 2);
        let missing = read_msh(&dir.join("missing.msh")).unwrap_err();
        assert!(matches!(missing, Error::Io(_)), "{missing}");
        std::fs::write(&path, "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n").unwrap();
        let e = read_msh(&path).unwrap_err().to_string();
        assert!(e.contains("square.msh") && e.contains("2.2"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A second-order mesh of the unit disk written the way Gmsh writes one (MSH 4.1,
    /// 6-node triangles, 3-node boundary lines on curve 1), from the disk generator with
    /// its boundary edge nodes on the circle; cells listed clockwise when `flip`.
    /// With `tamper`, cell 0 names the node of its edge 1–2 as that of its edge 0–1.
    fn quadratic_disk_text(
        rings: usize,
        flip: bool,
        tamper: bool,
    ) -> (String, TriangleMesh, QuadraticGeometry) {
        let mesh = TriangleMesh::disk([0.0, 0.0], 1.0, rings).unwrap();
        let geometry = QuadraticGeometry::circle(&mesh, [0.0, 0.0], 1.0).unwrap();
        let (nv, ne) = (mesh.vertex_count(), mesh.edge_count());
        let mut nodes = Vec::new();
        for v in mesh.vertices() {
            nodes.push(*v);
        }
        for e in 0..ne {
            let map_node = (0..mesh.cell_count())
                .find_map(|c| {
                    let k = mesh.local_edge(c, e)?;
                    Some(geometry.cell_map(&mesh, c).nodes()[3 + k])
                })
                .unwrap();
            nodes.push(map_node);
        }
        let mut text = String::from("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n");
        text += &format!("1 {} 1 {}\n2 1 0 {}\n", nv + ne, nv + ne, nv + ne);
        for i in 1..=nv + ne {
            text += &format!("{i}\n");
        }
        for p in &nodes {
            text += &format!("{:.17e} {:.17e} 0\n", p[0], p[1]);
        }
        let boundary: Vec<(usize, u32)> = mesh.boundary_edges().to_vec();
        let (nc, nb) = (mesh.cell_count(), boundary.len());
        text += &format!("$EndNodes\n$Elements\n2 {} 1 {}\n", nc + nb, nc + nb);
        text += &format!("1 1 8 {nb}\n");
        for (i, &(e, _)) in boundary.iter().enumerate() {
            let [a, b] = mesh.edges()[e];
            text += &format!("{} {} {} {}\n", i + 1, a + 1, b + 1, nv + e + 1);
        }
        text += &format!("2 1 9 {nc}\n");
        for c in 0..nc {
            let [a, b, d] = mesh.cell(c);
            let [mut e0, e1, e2] = mesh.cell_edges(c);
            if tamper && c == 0 {
                e0 = e1;
            }
            let line = if flip {
                // clockwise: a, d, b with the edges a–d, d–b, b–a
                [a, d, b, e2, e1, e0]
            } else {
                [a, b, d, e0, e1, e2]
            };
            let tags: Vec<String> = line
                .iter()
                .enumerate()
                .map(|(k, &i)| (if k < 3 { i + 1 } else { nv + i + 1 }).to_string())
                .collect();
            text += &format!("{} {}\n", nb + c + 1, tags.join(" "));
        }
        text += "$EndElements\n";
        (text, mesh, geometry)
    }

    /// A second-order Gmsh disk reads to the disk's corners and the same curved geometry
    /// (area to rounding, so O(h⁴) from π), whichever way its cells are listed; read as a
    /// straight mesh it is refused, and a first-order file is not a quadratic geometry.
    #[test]
    fn second_order_triangles_give_the_quadratic_geometry() {
        for flip in [false, true] {
            let (text, mesh, geometry) = quadratic_disk_text(8, flip, false);
            let (read, read_geometry) = parse_msh_quadratic(text.as_bytes()).unwrap();
            assert_eq!(read.vertex_count(), mesh.vertex_count());
            assert_eq!(read.cell_count(), mesh.cell_count());
            let (area, expected) = (read_geometry.area(&read), geometry.area(&mesh));
            assert!((area - expected).abs() < 1e-13, "{area} vs {expected}");
            assert!((area - std::f64::consts::PI).abs() < 3e-6, "{area}");
            // the boundary lines gave markers
            assert_eq!(read.boundary_edges().len(), mesh.boundary_edges().len());
            let straight = parse_msh(text.as_bytes()).unwrap_err().to_string();
            assert!(straight.contains("read_msh_quadratic"), "{straight}");
        }
        let first_order = parse_msh_quadratic(SQUARE.as_bytes())
            .unwrap_err()
            .to_string();
        assert!(first_order.contains("6-node"), "{first_order}");
        // two cells that disagree on an edge's middle node (an interior edge of ring 1)
        let (tampered, _, _) = quadratic_disk_text(2, false, true);
        let e = parse_msh_quadratic(tampered.as_bytes())
            .unwrap_err()
            .to_string();
        assert!(e.contains("two different middle nodes"), "{e}");
    }
}
