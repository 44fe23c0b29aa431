//! Glue between the generated fixed-size kernels and the runtime's flat buffers.

/// Copies an element matrix, row-major, into `out`.
#[inline(always)]
pub fn store_matrix<const R: usize, const C: usize>(k: &[[f64; C]; R], out: &mut [f64]) {
    for (i, row) in k.iter().enumerate() {
        out[i * C..(i + 1) * C].copy_from_slice(row);
    }
}

/// A scatter position: the index in a matrix's value array that one entry of one cell's
/// element matrix goes to. 32 bits, half of `usize`: an assembler holds one per cell
/// entry (32 million for 2 million P1–P0 triangles), and memory first touched costs
/// time here (`docs/multigrid.md`, "p1-p0 at 1025²"). The patterns refuse value arrays
/// of more than `u32::MAX` entries ([`position`]).
pub type Position = u32;

/// `index` as a [`Position`]: a pattern checks the largest index it will store this way
/// before it stores any.
///
/// # Errors
/// [`crate::Error::Input`] when `index` does not fit in 32 bits (an assembly of more than
/// 4.29·10⁹ cell entries or stored entries, 34 GB of values).
pub fn position(index: usize) -> crate::Result<Position> {
    Position::try_from(index).map_err(|_| {
        crate::Error::Input(format!(
            "an assembly that needs index {index} in its scatter positions, beyond the {} of 32 bits: too large to assemble (refine less or split the mesh)",
            Position::MAX
        ))
    })
}

/// Copies an element vector into `out`.
#[inline(always)]
pub fn store_vector<const R: usize>(k: &[f64; R], out: &mut [f64]) {
    out[..R].copy_from_slice(k);
}

/// Adds the element matrices of one block over every cell of `mesh` into `values`: cell
/// `c`'s entry `(i, j)` goes to `values[positions[c·stride + offset + i·C + j]]`.
///
/// Generated per block, so the kernel inlines into the cell loop and the block dispatch
/// happens once per assembly, not once per cell.
#[inline(always)]
pub fn add_matrices<G: crate::mesh::Mesh, const N: usize, const R: usize, const C: usize>(
    mesh: &G,
    positions: &[Position],
    stride: usize,
    offset: usize,
    values: &mut [f64],
    kernel: impl Fn(&[f64; N]) -> [[f64; C]; R],
) {
    let mut x = [0.0; N];
    for c in 0..mesh.cell_count() {
        mesh.cell_coordinates_into(c, &mut x);
        let k = kernel(&x);
        let at = &positions[c * stride + offset..][..R * C];
        for (&p, &v) in at.iter().zip(k.iter().flatten()) {
            values[p as usize] += v;
        }
    }
}

/// [`add_matrices`] for kernels that also take the cell's global vertex numbers (elements
/// with a per-cell DOF transformation, triangles only). A mesh without vertex numbers
/// gets NaN entries, which no solver mistakes for a result.
#[inline(always)]
pub fn add_matrices_on_cells<
    G: crate::mesh::Mesh,
    const N: usize,
    const R: usize,
    const C: usize,
>(
    mesh: &G,
    positions: &[Position],
    stride: usize,
    offset: usize,
    values: &mut [f64],
    kernel: impl Fn(&[f64; N], &[usize; 3]) -> [[f64; C]; R],
) {
    let mut x = [0.0; N];
    let mut g = [0usize; 3];
    for c in 0..mesh.cell_count() {
        mesh.cell_coordinates_into(c, &mut x);
        let k = if mesh.cell_vertex_numbers_into(c, &mut g) {
            kernel(&x, &g)
        } else {
            [[f64::NAN; C]; R]
        };
        let at = &positions[c * stride + offset..][..R * C];
        for (&p, &v) in at.iter().zip(k.iter().flatten()) {
            values[p as usize] += v;
        }
    }
}

#[cfg(test)]
mod position_tests {
    use super::*;

    #[test]
    fn positions_beyond_32_bits_are_refused_by_name() {
        assert_eq!(position(0).unwrap(), 0);
        assert_eq!(position(u32::MAX as usize).unwrap(), u32::MAX);
        let error = position(u32::MAX as usize + 1).unwrap_err().to_string();
        assert!(error.contains("too large to assemble"), "{error}");
    }
}
