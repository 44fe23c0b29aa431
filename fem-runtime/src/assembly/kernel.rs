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

/// The value array that element matrices and vectors are added into, entry by entry.
///
/// Safe code makes one from a `&mut [f64]` ([`Accumulator::new`]): it is then the only
/// access to the array. Parallel assembly gives each thread one over the same array
/// (`Accumulator::shared`, crate-internal and `unsafe`), where the colouring of the cells
/// guarantees that no two threads add to one entry: every write goes through the raw
/// pointer to its own entry, so no two `&mut` to the array (or to one element) exist at
/// once, as they would if each thread held the whole array as a slice.
pub struct Accumulator<'a> {
    start: *mut f64,
    len: usize,
    array: std::marker::PhantomData<&'a mut [f64]>,
}

impl<'a> Accumulator<'a> {
    /// Adds into `values`, which it borrows exclusively.
    pub fn new(values: &'a mut [f64]) -> Self {
        Self {
            start: values.as_mut_ptr(),
            len: values.len(),
            array: std::marker::PhantomData,
        }
    }

    /// One of several accumulators over the array of `len` values at `start`.
    ///
    /// # Safety
    /// For `'a` the array must be valid and accessed through accumulators alone, and no
    /// two of them (on any threads) may add to one entry unless one add happens before
    /// the other (no data race on any element).
    pub(crate) unsafe fn shared(start: *mut f64, len: usize) -> Self {
        Self {
            start,
            len,
            array: std::marker::PhantomData,
        }
    }

    /// Adds `value` to entry `index`.
    ///
    /// # Panics
    /// When `index` is out of the array's range, as slice indexing would.
    #[inline(always)]
    pub fn add(&mut self, index: usize, value: f64) {
        assert!(
            index < self.len,
            "scatter index {index} beyond {}",
            self.len
        );
        // SAFETY: in range (checked above), and by the construction's contract this
        // accumulator is the only access to the entry while it adds.
        unsafe { *self.start.add(index) += value }
    }
}

/// Copies an element vector into `out`.
#[inline(always)]
pub fn store_vector<const R: usize>(k: &[f64; R], out: &mut [f64]) {
    out[..R].copy_from_slice(k);
}

/// Adds the element matrices of one block over every cell of `mesh` into `values`: cell
/// `c`'s entry `(i, j)` goes to entry `positions[c·stride + offset + i·C + j]`.
///
/// Generated per block, so the kernel inlines into the cell loop and the block dispatch
/// happens once per assembly, not once per cell.
#[inline(always)]
pub fn add_matrices<G: crate::mesh::Mesh, const N: usize, const R: usize, const C: usize>(
    mesh: &G,
    positions: &[Position],
    stride: usize,
    offset: usize,
    values: &mut Accumulator,
    kernel: impl Fn(&[f64; N]) -> [[f64; C]; R],
) {
    let mut x = [0.0; N];
    for c in 0..mesh.cell_count() {
        mesh.cell_coordinates_into(c, &mut x);
        let k = kernel(&x);
        let at = &positions[c * stride + offset..][..R * C];
        for (&p, &v) in at.iter().zip(k.iter().flatten()) {
            values.add(p as usize, v);
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
    values: &mut Accumulator,
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
            values.add(p as usize, v);
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
