//! Marking: which cells to refine, given their squared indicators.

use crate::{Error, Result};

/// How cells are marked for refinement from their squared indicators `η_T²`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Marking {
    /// Dörfler (bulk) marking with parameter `θ ∈ (0, 1]`: the fewest cells, largest
    /// indicators first, whose squared indicators sum to at least `θ Σ_T η_T²`
    /// (Dörfler, SIAM J. Numer. Anal. 33 (1996); the marking of the optimality proofs).
    Dorfler(f64),
    /// Maximum marking with parameter `θ ∈ (0, 1]`: every cell with `η_T ≥ θ max η`
    /// (scikit-fem's `adaptive_theta`).
    Maximum(f64),
}

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
                order.truncate(count);
                order
            }
            Marking::Maximum(theta) => {
                let bar = theta * theta * largest;
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
