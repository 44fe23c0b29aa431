//! Glue between the generated fixed-size kernels and the runtime's flat buffers.

/// Copies an element matrix, row-major, into `out`.
#[inline(always)]
pub fn store_matrix<const R: usize, const C: usize>(k: &[[f64; C]; R], out: &mut [f64]) {
    for (i, row) in k.iter().enumerate() {
        out[i * C..(i + 1) * C].copy_from_slice(row);
    }
}

/// Copies an element vector into `out`.
#[inline(always)]
pub fn store_vector<const R: usize>(k: &[f64; R], out: &mut [f64]) {
    out[..R].copy_from_slice(k);
}
