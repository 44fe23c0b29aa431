//! Writing triangle meshes and fields on them as VTK unstructured grids (`.vtu`) for ParaView.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataSet, UnstructuredGridPiece, Version,
    VertexNumbers, Vtk,
};

use crate::error::{Error, Result};
use crate::mesh::triangle::TriangleMesh;

/// Writes an unstructured-grid `.vtu` (XML with inline base64 data) of the mesh, with
/// point data (one value per mesh vertex) and cell data (one value per cell).
///
/// The file is written under a temporary name in the same directory and renamed at the
/// end, so a failure never leaves a file that looks complete.
pub fn write_vtu(
    path: &Path,
    mesh: &TriangleMesh,
    point_data: &[(&str, &[f64])],
    cell_data: &[(&str, &[f64])],
) -> Result<()> {
    check_arrays("point", point_data, mesh.vertex_count(), "vertices")?;
    check_arrays("cell", cell_data, mesh.cell_count(), "cells")?;
    let vtk = model(mesh, point_data, cell_data);

    let name = path
        .file_name()
        .ok_or_else(|| Error::Io(format!("{} names no file", path.display())))?;
    let temporary = temporary_path(path, &name.to_string_lossy());
    let written = (|| -> std::result::Result<(), String> {
        let file = std::fs::File::create(&temporary).map_err(|e| e.to_string())?;
        let mut writer = std::io::BufWriter::new(file);
        vtk.write_xml(&mut writer).map_err(|e| e.to_string())?;
        writer.flush().map_err(|e| e.to_string())?;
        writer.get_ref().sync_all().map_err(|e| e.to_string())?;
        std::fs::rename(&temporary, path).map_err(|e| e.to_string())
    })();
    written.map_err(|e| {
        // the partial file must not stay behind; failing to remove it changes nothing
        let _ = std::fs::remove_file(&temporary);
        Error::Io(format!("cannot write {}: {e}", path.display()))
    })
}

/// Rejects arrays of the wrong length, empty names and names used twice.
fn check_arrays(kind: &str, arrays: &[(&str, &[f64])], expected: usize, what: &str) -> Result<()> {
    for (i, &(name, values)) in arrays.iter().enumerate() {
        if name.is_empty() {
            return Err(Error::Input(format!(
                "{kind} data array {i} has an empty name"
            )));
        }
        if values.len() != expected {
            return Err(Error::Input(format!(
                "{kind} data `{name}` has {} values, but the mesh has {expected} {what}",
                values.len()
            )));
        }
        if arrays[..i].iter().any(|&(other, _)| other == name) {
            return Err(Error::Input(format!("{kind} data `{name}` is given twice")));
        }
    }
    Ok(())
}

/// A name beside `path` that no other writer in this process uses at the same time.
fn temporary_path(path: &Path, name: &str) -> PathBuf {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    path.with_file_name(format!(".{name}.{}.{n}.tmp", std::process::id()))
}

fn model(mesh: &TriangleMesh, point_data: &[(&str, &[f64])], cell_data: &[(&str, &[f64])]) -> Vtk {
    let points: Vec<f64> = mesh
        .vertices()
        .iter()
        .flat_map(|p| [p[0], p[1], 0.0])
        .collect();
    let connectivity: Vec<u64> = mesh.cells().iter().flatten().map(|&v| v as u64).collect();
    let offsets: Vec<u64> = (1..=mesh.cell_count() as u64).map(|c| 3 * c).collect();
    let array =
        |&(name, values): &(&str, &[f64])| Attribute::scalars(name, 1).with_data(values.to_vec());
    let piece = UnstructuredGridPiece {
        points: points.into(),
        cells: Cells {
            cell_verts: VertexNumbers::XML {
                connectivity,
                offsets,
            },
            types: vec![CellType::Triangle; mesh.cell_count()],
        },
        data: Attributes {
            point: point_data.iter().map(array).collect(),
            cell: cell_data.iter().map(array).collect(),
        },
    };
    Vtk {
        version: Version::new((1, 0)),
        title: String::new(),
        byte_order: ByteOrder::LittleEndian,
        file_path: None,
        data: DataSet::inline(piece),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::triangle::Diagonal;
    use vtkio::model::DataArray;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("fem-vtk-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn values(attribute: &Attribute) -> (String, Vec<f64>) {
        match attribute {
            Attribute::DataArray(DataArray { name, data, .. }) => {
                (name.clone(), data.clone().cast_into::<f64>().unwrap())
            }
            other => panic!("unexpected attribute {other:?}"),
        }
    }

    #[test]
    fn round_trip_through_vtkio() {
        let dir = scratch("round-trip");
        let path = dir.join("mesh.vtu");
        let mesh = TriangleMesh::rectangle(0.0, 2.0, -1.0, 1.0, 3, 2, Diagonal::Crossed).unwrap();
        let u: Vec<f64> = mesh
            .vertices()
            .iter()
            .map(|p| p[0] * p[0] - 0.5 * p[1])
            .collect();
        let ids: Vec<f64> = (0..mesh.vertex_count()).map(|v| v as f64).collect();
        let area: Vec<f64> = (0..mesh.cell_count()).map(|c| mesh.area(c)).collect();
        write_vtu(&path, &mesh, &[("u", &u), ("id", &ids)], &[("area", &area)]).unwrap();

        let read = Vtk::import(&path).unwrap();
        let DataSet::UnstructuredGrid { pieces, .. } = read.data else {
            panic!("not an unstructured grid")
        };
        let piece = pieces[0].clone().into_loaded_piece_data(None).unwrap();
        let points = piece.points.cast_into::<f64>().unwrap();
        let expected: Vec<f64> = mesh
            .vertices()
            .iter()
            .flat_map(|p| [p[0], p[1], 0.0])
            .collect();
        assert_eq!(points, expected);
        let (connectivity, offsets) = piece.cells.cell_verts.into_xml();
        let cells: Vec<u64> = mesh.cells().iter().flatten().map(|&v| v as u64).collect();
        assert_eq!(connectivity, cells);
        assert_eq!(offsets.len(), mesh.cell_count());
        assert!(piece.cells.types.iter().all(|&t| t == CellType::Triangle));
        let point: Vec<_> = piece.data.point.iter().map(values).collect();
        assert_eq!(point, vec![("u".to_string(), u), ("id".to_string(), ids)]);
        let cell: Vec<_> = piece.data.cell.iter().map(values).collect();
        assert_eq!(cell, vec![("area".to_string(), area)]);
        // only the finished file is left
        let names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("mesh.vtu")]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn bad_arrays_and_paths_are_errors() {
        let dir = scratch("errors");
        let mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 2, 2, Diagonal::Right).unwrap();
        let short = vec![0.0; 3];
        let path = dir.join("bad.vtu");
        let e = write_vtu(&path, &mesh, &[("pressure", &short)], &[])
            .unwrap_err()
            .to_string();
        assert!(e.contains("pressure") && e.contains("vertices"), "{e}");
        let e = write_vtu(&path, &mesh, &[], &[("indicator", &short)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("indicator") && e.contains("cells"), "{e}");
        let ok = vec![0.0; mesh.vertex_count()];
        let e = write_vtu(&path, &mesh, &[("u", &ok), ("u", &ok)], &[])
            .unwrap_err()
            .to_string();
        assert!(e.contains("twice"), "{e}");
        assert!(!path.exists());
        let nowhere = dir.join("no-such-directory").join("mesh.vtu");
        let e = write_vtu(&nowhere, &mesh, &[], &[]).unwrap_err();
        assert!(matches!(e, Error::Io(_)), "{e}");
        // a directory in the way: writing succeeds, renaming onto it fails, and the
        // temporary file is removed
        let blocked = dir.join("blocked.vtu");
        std::fs::create_dir_all(blocked.join("inside")).unwrap();
        let e = write_vtu(&blocked, &mesh, &[], &[]).unwrap_err();
        assert!(matches!(e, Error::Io(_)), "{e}");
        let names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("blocked.vtu")]);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
