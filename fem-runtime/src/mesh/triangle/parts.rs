//! Named parts of a triangle mesh: Gmsh physical groups (read by
//! [`crate::mesh::gmsh`]) or the sides a built-in generator names, and the choice of
//! boundary parts by name (the Dirichlet part of a scene).
//!
//! A boundary part is a set of boundary markers: the edges whose marker is one of them.
//! Markers pass to edge halves under refinement ([`TriangleMesh::refine`]) and the names
//! are kept with the mesh, so a part chosen on a coarse mesh is the same part of the
//! boundary on every refinement.

use super::*;

/// A named group of a mesh: a Gmsh physical group, or a side a generator names.
#[derive(Clone, Debug, PartialEq)]
pub struct NamedGroup {
    /// The name (a Gmsh physical name).
    pub name: String,
    /// 0 for points, 1 for curves (boundary parts), 2 for surfaces.
    pub dimension: usize,
    /// For a curve group: the boundary markers of its edges (the group is the boundary
    /// edges whose marker is one of these). Empty for other dimensions.
    pub markers: Vec<u32>,
    /// The interior edges of a curve group (lines of embedded curves), which a boundary
    /// part leaves out: reported so that a part with them can be warned about.
    pub interior_edges: usize,
    /// Why the group cannot be chosen by its markers, when the file does not say which
    /// edges are in it (a Gmsh file without `$Entities`, see
    /// [`crate::mesh::gmsh::parse_msh`]).
    pub ambiguity: Option<String>,
}

impl TriangleMesh {
    /// The mesh's named groups, in the order they were given.
    pub fn named_groups(&self) -> &[NamedGroup] {
        &self.groups
    }

    /// The names of the boundary parts (curve groups), in the order they were given.
    pub fn boundary_part_names(&self) -> Vec<&str> {
        self.groups
            .iter()
            .filter(|g| g.dimension == 1)
            .map(|g| g.name.as_str())
            .collect()
    }

    /// Replaces the mesh's named groups (kept by refinement).
    pub(crate) fn set_named_groups(&mut self, groups: Vec<NamedGroup>) {
        self.groups = groups;
    }

    /// The mesh with boundary parts named: each `(name, markers)` names the boundary
    /// edges whose marker is one of `markers`. Replaces the parts named before.
    ///
    /// # Errors
    /// [`Error::Mesh`] for an empty or repeated name, or a part without markers.
    pub fn with_boundary_names(mut self, parts: &[(&str, &[u32])]) -> Result<Self> {
        let mut groups: Vec<NamedGroup> = Vec::with_capacity(parts.len());
        for &(name, markers) in parts {
            if name.trim().is_empty() {
                return Err(mesh_error("a boundary part needs a non-empty name".into()));
            }
            if groups.iter().any(|g| g.name == name) {
                return Err(mesh_error(format!(
                    "the boundary part name `{name}` is given twice"
                )));
            }
            if markers.is_empty() {
                return Err(mesh_error(format!(
                    "the boundary part `{name}` has no markers"
                )));
            }
            groups.push(NamedGroup {
                name: name.to_string(),
                dimension: 1,
                markers: markers.to_vec(),
                interior_edges: 0,
                ambiguity: None,
            });
        }
        self.groups = groups;
        Ok(self)
    }

    /// The boundary markers of the parts called `names` (sorted, unique).
    ///
    /// # Errors
    /// [`Error::Input`] for an empty list (no part chosen), a name the mesh does not
    /// have (the message lists the names it has, and says so when the name is a
    /// number: Gmsh groups are chosen by physical name, not by tag), the name of a
    /// surface or point group, and a curve group that cannot be told apart by markers
    /// ([`NamedGroup::ambiguity`]).
    pub fn boundary_part_markers<S: AsRef<str>>(&self, names: &[S]) -> Result<Vec<u32>> {
        if names.is_empty() {
            return Err(Error::Input("no boundary part is named".into()));
        }
        let known = self.boundary_part_names();
        let listing = if known.is_empty() {
            "the mesh names no boundary parts".to_string()
        } else {
            format!(
                "the mesh's boundary parts are {}",
                known
                    .iter()
                    .map(|n| format!("`{n}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        };
        let mut markers = Vec::new();
        for name in names {
            let name = name.as_ref();
            let curves: Vec<&NamedGroup> = self
                .groups
                .iter()
                .filter(|g| g.dimension == 1 && g.name == name)
                .collect();
            if curves.is_empty() {
                let kind = self
                    .groups
                    .iter()
                    .find(|g| g.name == name)
                    .map(|g| match g.dimension {
                        0 => "a group of points (a 0-D physical group)",
                        3 => "a volume (a 3-D physical group)",
                        _ => "a surface (a 2-D physical group)",
                    });
                let message = match kind {
                    Some(kind) => {
                        format!("`{name}` names {kind}, not a part of the boundary; {listing}")
                    }
                    None => match name.trim().parse::<u32>() {
                        Ok(tag) => {
                            let holders: Vec<String> = self
                                .groups
                                .iter()
                                .filter(|g| g.dimension == 1 && g.markers.contains(&tag))
                                .map(|g| format!("`{}`", g.name))
                                .collect();
                            let used = self.boundary_edges.iter().any(|&(_, m)| m == tag);
                            let about = if !holders.is_empty() {
                                format!(
                                    "; the edges of marker {tag} belong to {}",
                                    holders.join(", ")
                                )
                            } else if used {
                                format!("; boundary edges with marker {tag} exist, but no name is given to them: give their curves a physical name (in Gmsh: Physical Curve(\"name\") = {{…}})")
                            } else {
                                String::new()
                            };
                            format!(
                                "no boundary part is named `{name}`: boundary parts are chosen by name, not by tag or marker number{about}; {listing}"
                            )
                        }
                        Err(_) => format!("no boundary part is named `{name}`; {listing}"),
                    },
                };
                return Err(Error::Input(message));
            }
            for group in curves {
                if let Some(why) = &group.ambiguity {
                    return Err(Error::Input(format!(
                        "the boundary part `{name}` cannot be chosen: {why}"
                    )));
                }
                markers.extend_from_slice(&group.markers);
            }
        }
        markers.sort_unstable();
        markers.dedup();
        Ok(markers)
    }

    /// The interior edges (of embedded curves) of each of the groups `names` that has
    /// any, as `(name, count)`: a boundary part holds boundary edges only, so these are
    /// left out of it (unknown names are skipped: [`TriangleMesh::boundary_part_markers`]
    /// reports them).
    pub fn interior_edges_of<S: AsRef<str>>(&self, names: &[S]) -> Vec<(String, usize)> {
        names
            .iter()
            .filter_map(|name| {
                let name = name.as_ref();
                let count: usize = self
                    .groups
                    .iter()
                    .filter(|g| g.dimension == 1 && g.name == name)
                    .map(|g| g.interior_edges)
                    .sum();
                (count > 0).then(|| (name.to_string(), count))
            })
            .collect()
    }

    /// The number of boundary edges whose marker is one of `markers`.
    pub fn boundary_edges_with_markers(&self, markers: &[u32]) -> usize {
        self.boundary_edges
            .iter()
            .filter(|&&(_, m)| markers.contains(&m))
            .count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn length(m: &TriangleMesh, markers: &[u32]) -> f64 {
        m.boundary_edges()
            .iter()
            .filter(|&&(_, mk)| markers.contains(&mk))
            .map(|&(e, _)| {
                let [a, b] = m.edges()[e];
                dist2(m.vertices()[a], m.vertices()[b]).sqrt()
            })
            .sum()
    }

    #[test]
    fn generators_name_their_sides() {
        let m = TriangleMesh::rectangle(0.0, 3.0, 0.0, 1.0, 6, 2, Diagonal::Right).unwrap();
        assert_eq!(m.boundary_part_names(), ["bottom", "right", "top", "left"]);
        for (name, expected) in [("bottom", 3.0), ("right", 1.0), ("top", 3.0), ("left", 1.0)] {
            let markers = m.boundary_part_markers(&[name]).unwrap();
            assert!((length(&m, &markers) - expected).abs() < 1e-13, "{name}");
        }
        let sides = m.boundary_part_markers(&["left", "right", "left"]).unwrap();
        assert!((length(&m, &sides) - 2.0).abs() < 1e-13);
        let disk = TriangleMesh::disk([0.0, 0.0], 1.0, 3).unwrap();
        let circle = disk.boundary_part_markers(&["circle"]).unwrap();
        assert_eq!(
            disk.boundary_edges_with_markers(&circle),
            disk.boundary_edges().len()
        );
        let l = TriangleMesh::l_shape(2).unwrap();
        let outer = l.boundary_part_markers(&["outer"]).unwrap();
        let reentrant = l.boundary_part_markers(&["reentrant"]).unwrap();
        assert!((length(&l, &outer) - 6.0).abs() < 1e-13);
        assert!((length(&l, &reentrant) - 2.0).abs() < 1e-13);
    }

    #[test]
    fn refinement_keeps_the_parts() {
        let m = TriangleMesh::rectangle(0.0, 1.0, 0.0, 2.0, 2, 3, Diagonal::Alternating).unwrap();
        let fine = m.refine_uniformly().refine(&[0, 5, 7]).unwrap().0;
        assert_eq!(fine.named_groups(), m.named_groups());
        for (name, expected) in [("bottom", 1.0), ("right", 2.0), ("top", 1.0), ("left", 2.0)] {
            let markers = fine.boundary_part_markers(&[name]).unwrap();
            assert!((length(&fine, &markers) - expected).abs() < 1e-13, "{name}");
        }
    }

    #[test]
    fn bad_names_are_clear_errors() {
        let m = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 2, 2, Diagonal::Right).unwrap();
        let e = m.boundary_part_markers(&["outer"]).unwrap_err().to_string();
        assert!(
            e.contains("`outer`") && e.contains("`left`") && e.contains("`top`"),
            "{e}"
        );
        let e = m.boundary_part_markers(&["3"]).unwrap_err().to_string();
        assert!(
            e.contains("not by tag or marker") && e.contains("marker 3 belong to `top`"),
            "{e}"
        );
        let none: [&str; 0] = [];
        assert!(m.boundary_part_markers(&none).is_err());
        let mut named = m.clone();
        named.set_named_groups(vec![NamedGroup {
            name: "domain".into(),
            dimension: 2,
            markers: Vec::new(),
            interior_edges: 0,
            ambiguity: None,
        }]);
        let e = named
            .boundary_part_markers(&["domain"])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("surface") && e.contains("names no boundary parts"),
            "{e}"
        );
        for parts in [
            &[("", &[1u32][..])][..],
            &[("a", &[1][..]), ("a", &[2][..])],
            &[("a", &[][..])],
        ] {
            assert!(m.clone().with_boundary_names(parts).is_err());
        }
        let renamed = m.with_boundary_names(&[("walls", &[2, 4])]).unwrap();
        assert_eq!(renamed.boundary_part_markers(&["walls"]).unwrap(), [2, 4]);
    }
}
