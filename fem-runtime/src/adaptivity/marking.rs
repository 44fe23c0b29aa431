//! Marking: which cells to refine, given their squared indicators.

use crate::{Error, Result};

/// How cells are marked for refinement from their squared indicators `η_T²`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Marking {
    /// Dörfler (bulk) marking with parameter `θ ∈ (0, 1]`: the fewest cells, largest
    /// indicators first, whose squared indicators sum to at least `θ Σ_T η_T²`
    /// (Dörfler, SIAM J. Numer. Anal. 33 (1996); the marking of the optimality proofs),
    /// and the cells tied with the last of them ([`TIE`]).
    Dorfler(f64),
    /// Maximum marking with parameter `θ ∈ (0, 1]`: every cell with `η_T ≥ θ max η`
    /// (scikit-fem's `adaptive_theta`), ties with the bar included ([`TIE`]).
    Maximum(f64),
}

/// The relative difference of squared indicators below which two cells count as tied
/// and are marked together. A symmetric problem has its indicators in equal pairs, equal
/// only to the rounding of the solve: marking one cell of a pair and not the other
/// breaks the mesh's symmetry, and which one depends on that rounding, so solves that
/// agree to their tolerance (the native solver and PETSc, on any number of ranks) refined
/// different cells (an adaptive Euler–Bernoulli beam: 57 cells natively, 58 and 60 on one
/// and two ranks). 10⁻⁶ lies far above a converged solve's rounding of an indicator
/// (10⁻¹⁰ relative) and marks no cell that is not tied in substance.
pub const TIE: f64 = 1e-6;

impl Default for Marking {
    /// Dörfler marking with `θ = ½`.
    fn default() -> Self {
        Marking::Dorfler(0.5)
    }
}

impl Marking {
    /// The marking parameter θ.
    pub fn theta(self) -> f64 {
        match self {
            Marking::Dorfler(t) | Marking::Maximum(t) => t,
        }
    }

    /// The marked cells (indices into `indicators`, the squared indicators), largest
    /// indicator first; none when every indicator is zero.
    ///
    /// # Errors
    /// [`Error::Input`] for θ outside `(0, 1]` and for an indicator that is negative or
    /// not finite (the message names the cell).
    pub fn mark(self, indicators: &[f64]) -> Result<Vec<usize>> {
        let theta = self.theta();
        if !(theta > 0.0 && theta <= 1.0) {
            return Err(Error::Input(format!(
                "the marking parameter θ = {theta} is outside (0, 1]"
            )));
        }
        if let Some(c) = indicators
            .iter()
            .position(|e| !(e.is_finite() && *e >= 0.0))
        {
            return Err(Error::Input(format!(
                "the squared indicator of cell {c} is {}: an indicator is a finite sum of squares",
                indicators[c]
            )));
        }
        let mut order: Vec<usize> = (0..indicators.len()).collect();
        order.sort_by(|&a, &b| indicators[b].total_cmp(&indicators[a]).then(a.cmp(&b)));
        let largest = order.first().map_or(0.0, |&c| indicators[c]);
        if largest == 0.0 {
            return Ok(Vec::new());
        }
        Ok(match self {
            Marking::Dorfler(theta) => {
                let goal = theta * indicators.iter().sum::<f64>();
                let mut sum = 0.0;
                let count = order
                    .iter()
                    .position(|&c| {
                        sum += indicators[c];
                        sum >= goal
                    })
                    .map_or(order.len(), |k| k + 1);
                let last = indicators[order[count - 1]];
                let tied = order[count..]
                    .iter()
                    .take_while(|&&c| indicators[c] >= last * (1.0 - TIE))
                    .count();
                order.truncate(count + tied);
                order
            }
            Marking::Maximum(theta) => {
                let bar = theta * theta * largest * (1.0 - TIE);
                order.retain(|&c| indicators[c] >= bar);
                order
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dorfler_marks_the_fewest_cells_that_hold_the_share() {
        let eta = [1.0, 4.0, 0.5, 2.0, 2.5];
        // total 10: θ = ½ needs 5 → 4 + 2.5
        assert_eq!(Marking::Dorfler(0.5).mark(&eta).unwrap(), vec![1, 4]);
        // θ = 0.65 needs 6.5 → 4 + 2.5 (6.5)
        assert_eq!(Marking::Dorfler(0.65).mark(&eta).unwrap(), vec![1, 4]);
        assert_eq!(Marking::Dorfler(0.66).mark(&eta).unwrap(), vec![1, 4, 3]);
        assert_eq!(Marking::Dorfler(1.0).mark(&eta).unwrap().len(), 5);
    }

    #[test]
    fn cells_tied_to_rounding_are_marked_together() {
        // a symmetric pair, equal to rounding: θ = 0.3 of 5 needs one of them, and
        // whichever rounding made larger, both are marked
        for pair in [[2.0, 2.0 * (1.0 + 1e-12)], [2.0 * (1.0 + 1e-12), 2.0]] {
            let eta = [pair[0], 1.0, pair[1]];
            let mut marked = Marking::Dorfler(0.3).mark(&eta).unwrap();
            marked.sort_unstable();
            assert_eq!(marked, vec![0, 2], "{pair:?}");
            let mut marked = Marking::Maximum(1.0).mark(&eta).unwrap();
            marked.sort_unstable();
            assert_eq!(marked, vec![0, 2], "{pair:?}");
        }
        // apart by more than the tie: the fewest cells
        let eta = [2.0, 1.0, 2.0 * (1.0 - 1e-3)];
        assert_eq!(Marking::Dorfler(0.3).mark(&eta).unwrap(), vec![0]);
        assert_eq!(Marking::Maximum(1.0).mark(&eta).unwrap(), vec![0]);
    }

    #[test]
    fn maximum_marks_cells_near_the_largest() {
        let eta = [1.0, 4.0, 0.5, 2.0, 2.5];
        // η ≥ ½·2 = 1 ⇔ η² ≥ 1
        assert_eq!(Marking::Maximum(0.5).mark(&eta).unwrap(), vec![1, 4, 3, 0]);
        assert_eq!(Marking::Maximum(1.0).mark(&eta).unwrap(), vec![1]);
    }

    #[test]
    fn bad_input_is_an_error_and_zero_marks_nothing() {
        assert!(Marking::Dorfler(0.0).mark(&[1.0]).is_err());
        assert!(Marking::Maximum(1.5).mark(&[1.0]).is_err());
        assert!(Marking::Dorfler(f64::NAN).mark(&[1.0]).is_err());
        let e = Marking::Dorfler(0.5).mark(&[1.0, f64::NAN]).unwrap_err();
        assert!(e.to_string().contains("cell 1"), "{e}");
        assert!(Marking::Dorfler(0.5).mark(&[1.0, -1.0]).is_err());
        assert!(Marking::Dorfler(0.5).mark(&[0.0, 0.0]).unwrap().is_empty());
        assert!(Marking::Dorfler(0.5).mark(&[]).unwrap().is_empty());
    }
}
