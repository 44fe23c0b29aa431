//! The memory a solve may plan to use, and the estimate of what it will use, checked
//! before any work: an allocation that fails inside a factorization aborts the process,
//! and an estimate that the machine cannot hold is refused with its figure instead.

use crate::error::{Error, Result};

/// The most memory a solve may plan to use, on any machine.
pub const MEMORY_LIMIT_BYTES: f64 = 16.0 * (1u64 << 30) as f64;

/// The share of the memory available now (`MemAvailable` of `/proc/meminfo`) a solve
/// may plan to use: the estimates are within about 20 % of the measured peaks.
pub const AVAILABLE_MEMORY_SHARE: f64 = 0.8;

/// The most memory a solve may plan to use here: [`MEMORY_LIMIT_BYTES`], or
/// [`AVAILABLE_MEMORY_SHARE`] of the memory available if that is less: the kernel's
/// `MemAvailable` (`/proc/meminfo`, in KiB) and a container's limit (cgroup v2
/// `memory.max`, v1 `memory.limit_in_bytes`), which `/proc/meminfo` does not show (a
/// fixed limit alone let a 28 GB run start on a 23 GB machine, which the kernel then
/// killed). What cannot be read does not lower it.
pub fn memory_limit_bytes() -> f64 {
    MEMORY_LIMIT_BYTES
        .min(available_memory_bytes().map_or(f64::INFINITY, |b| AVAILABLE_MEMORY_SHARE * b))
}

/// The memory available to this process, as [`memory_limit_bytes`] reads it, in bytes;
/// `None` where none of its sources can be read.
fn available_memory_bytes() -> Option<f64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|text| {
            text.lines()
                .find_map(|line| line.strip_prefix("MemAvailable:"))
                .and_then(|rest| rest.trim().strip_suffix("kB"))
                .and_then(|kb| kb.trim().parse::<f64>().ok())
                .map(|kb| kb * 1024.0)
        });
    // "max" (no limit) does not parse, nor does a missing file
    let cgroup = [
        "/sys/fs/cgroup/memory.max",
        "/sys/fs/cgroup/memory/memory.limit_in_bytes",
    ]
    .iter()
    .find_map(|path| {
        std::fs::read_to_string(path)
            .ok()
            .and_then(|text| text.trim().parse::<f64>().ok())
    });
    match (meminfo, cgroup) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// "the 12.3 GB this solver allows itself here (80 % of the memory available now)" or,
/// where the fixed limit is the lower one, "… (its fixed limit)", for messages.
pub fn memory_limit_text(limit: f64) -> String {
    let why = if limit < MEMORY_LIMIT_BYTES {
        format!(
            "{:.0} % of the memory available now",
            100.0 * AVAILABLE_MEMORY_SHARE
        )
    } else {
        "its fixed limit".to_string()
    };
    format!(
        "the {:.1} GB this solver allows itself here ({why})",
        limit / 1e9
    )
}

/// "needs about 23.5 GB of memory, more than the 17.2 GB this solver allows itself here
/// (…)" when an estimated peak of `bytes` exceeds [`memory_limit_bytes`]; `None` when it
/// fits.
pub fn beyond_memory(bytes: f64) -> Option<String> {
    let limit = memory_limit_bytes();
    (bytes > limit).then(|| {
        format!(
            "needs about {:.1} GB of memory, more than {}",
            bytes / 1e9,
            memory_limit_text(limit)
        )
    })
}

/// The peak memory of a solve per cell of its finest mesh, `per_cell + per_cell_log ·
/// log₂(cells)` bytes (a direct factor's fill grows like `N log N` in 2D), and at least
/// `floor` per cell. A pair's measured peaks give it its own; [`MemoryModel::of_model`]
/// is a generous default from the model's local system.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MemoryModel {
    /// Bytes per cell.
    pub per_cell: f64,
    /// Bytes per cell per doubling of the cell count.
    pub per_cell_log: f64,
    /// The least bytes per cell.
    pub floor: f64,
}

impl MemoryModel {
    /// `bytes` per cell, whatever the size.
    pub const fn per_cell(bytes: f64) -> Self {
        Self {
            per_cell: bytes,
            per_cell_log: 0.0,
            floor: 0.0,
        }
    }

    /// A default for model `M` from the size `L` of its local system (the local DOFs of
    /// all fields on a cell): `100 L²` bytes plus `10 L²` per doubling of the cells.
    /// Measured peaks lie at or below it (membrane P1–P0 1.3 kB a cell at 8M cells
    /// against 5 kB here; Mindlin's 9.6 kB at 131k against 36 kB); Argyris plates, whose
    /// vertices couple many DOFs, take their measured model.
    pub fn of_model<M: crate::Model>() -> Self {
        let local: usize = M::FIELDS
            .iter()
            .map(|f| f.element.local_dof_count(M::CELL))
            .sum();
        let entries = (local * local) as f64;
        Self {
            per_cell: 100.0 * entries,
            per_cell_log: 10.0 * entries,
            floor: 0.0,
        }
    }

    /// The estimated peak in bytes of a solve whose finest mesh has `cells` cells.
    pub fn bytes(&self, cells: usize) -> f64 {
        let cells = cells as f64;
        cells * (self.per_cell + self.per_cell_log * cells.max(1.0).log2()).max(self.floor)
    }
}

/// An error naming `what` (the input that sets the size, e.g. "--mesh-size 512 with
/// p2-p0") when `bytes` exceed what the solver allows itself.
///
/// # Errors
/// [`Error::Input`] with the figure.
pub fn check_memory(bytes: f64, what: &str) -> Result<()> {
    match beyond_memory(bytes) {
        Some(m) => Err(Error::Input(format!(
            "{what} {m}; a coarser mesh does (the memory grows about 4× per halving of h in 2D)"
        ))),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_estimate_grows_with_the_cells_and_the_limit_is_named() {
        let m = MemoryModel {
            per_cell: 1e3,
            per_cell_log: 1e2,
            floor: 0.0,
        };
        assert_eq!(m.bytes(1), 1e3);
        assert!((m.bytes(1024) - 1024.0 * (1e3 + 1e3)).abs() < 1e-6);
        let floored = MemoryModel { floor: 5e3, ..m };
        assert_eq!(floored.bytes(2), 2.0 * 5e3);
        assert!(check_memory(1e3, "a small mesh").is_ok());
        let e = check_memory(1e15, "--mesh-size 9").unwrap_err().to_string();
        assert!(e.contains("--mesh-size 9 needs about 1000000.0 GB"), "{e}");
    }
}
