//! Memory needed by an analysis, estimated before anything large is allocated, and the limit it is
//! checked against.
//!
//! A failed allocation aborts the process (Rust's default), which from Python is a crash without a
//! message. So the solver refuses, with [`Error::OutOfMemory`], a model whose estimated memory
//! exceeds the limit, at two points:
//!
//! 1. [`MemoryEstimate::of_mesh`], before the system is built: nodes, elements, the per-element
//!    buffers, the sparsity pattern (`36 (N + 8 E)` entries for `N` nodes and `E` quadrilaterals:
//!    each node couples with itself and, through its elements, with about 8 neighbours), the
//!    temporary lists that build it (`576` entries per element), and a typical fill of the sparse
//!    factor (see [`typical_factor_entries`]).
//! 2. [`check_factor`], after the symbolic analysis: the exact number of entries of the factor
//!    (known before its values are allocated).
//!
//! The limit ([`memory_limit`]) is, in this order: the environment variable
//! `TAPESPRING_MEMORY_LIMIT` (bytes, or a number with a unit `K`, `M`, `G`, `T`, e.g. `"6G"`; `"none"`
//! disables the check); else the memory available to the process (`MemAvailable` of
//! `/proc/meminfo`, and the cgroup's `memory.max - memory.current` if smaller); else
//! [`FALLBACK_LIMIT`].

use crate::element::shell::{ElementMatrix, ElementStress, ElementVector, ShellElement};
use crate::error::{Error, Result};

/// Name of the environment variable that sets the memory limit.
pub const LIMIT_VARIABLE: &str = "TAPESPRING_MEMORY_LIMIT";

/// Limit used where the available memory cannot be read (not Linux): 8 GiB \[bytes\].
pub const FALLBACK_LIMIT: u64 = 8 << 30;

/// Bytes per entry of the tangent's pattern held by the assembly and the linear solver: row index
/// (pattern and faer's copy), values of `K`, of its symmetric triangle and of GMRES's copy, the
/// source map of the triangle and the transpose map built with it (about 60 bytes).
const BYTES_PER_MATRIX_ENTRY: f64 = 64.0;

/// Bytes per entry of the factor: its value, and (a part of) its row index.
const BYTES_PER_FACTOR_ENTRY: f64 = 12.0;

/// Memory an analysis of a mesh needs (estimate).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MemoryEstimate {
    /// Nodes.
    pub nodes: usize,
    /// Elements.
    pub elements: usize,
    /// Degrees of freedom (six per node; the free ones are fewer).
    pub dofs: usize,
    /// Entries of the tangent's sparsity pattern.
    pub matrix_entries: f64,
    /// Entries of the sparse factor (typical fill of a shell mesh, or the exact count).
    pub factor_entries: f64,
    /// Total \[bytes\].
    pub bytes: f64,
}

/// Typical number of entries of the LDL^T factor of the tangent of a quadrilateral shell mesh of
/// `nodes` nodes with an AMD ordering: `36 * 2.5 N log2 N` (six DOFs per node). Measured with
/// faer's AMD: 1.9 to 3.0 `N log2 N` node blocks on square plates of 441 to 160 801 nodes, 1.2 to
/// 2.2 on tape springs of 561 to 42 021 nodes (long strips, whose fill grows only as
/// `N * width`); nested dissection of a `k x k` grid gives `31/8 N log2 N` (George 1973).
#[must_use]
pub fn typical_factor_entries(nodes: usize) -> f64 {
    #[allow(clippy::cast_precision_loss)]
    let n = nodes as f64;
    36.0 * 2.5 * n * n.max(2.0).log2()
}

impl MemoryEstimate {
    /// The estimate for a mesh of `nodes` nodes and `elements` quadrilaterals, before anything is
    /// built.
    #[must_use]
    #[allow(clippy::cast_precision_loss)]
    pub fn of_mesh(nodes: usize, elements: usize) -> Self {
        let (n, e) = (nodes as f64, elements as f64);
        let matrix_entries = 36.0 * (n + 8.0 * e);
        let factor_entries = typical_factor_entries(nodes);
        // Per element: the element itself, its force and tangent buffers, its 24 x 24 slot map,
        // its stresses (mixed iteration), owners; and the 576 pushes per element of the pattern's
        // build (usize).
        let per_element = (std::mem::size_of::<ShellElement>()
            + 2 * std::mem::size_of::<ElementVector>()
            + std::mem::size_of::<ElementMatrix>()
            + 576 * 4
            + std::mem::size_of::<ElementStress>()
            + 64) as f64
            + 576.0 * 8.0;
        // Per node: states (positions, rotations, velocities, accelerations and their copies for
        // rejected increments), triads, masses, DOF maps, recorded fields.
        let per_node = 1024.0;
        let bytes = per_element * e
            + per_node * n
            + BYTES_PER_MATRIX_ENTRY * matrix_entries
            + BYTES_PER_FACTOR_ENTRY * factor_entries;
        Self {
            nodes,
            elements,
            dofs: nodes.saturating_mul(6),
            matrix_entries,
            factor_entries,
            bytes,
        }
    }

    /// Checks the estimate against [`memory_limit`].
    ///
    /// # Errors
    /// [`Error::OutOfMemory`] if it exceeds the limit (the message gives the sizes, the limit and
    /// how to raise it); [`Error::InvalidParameter`] if `TAPESPRING_MEMORY_LIMIT` cannot be read.
    pub fn check(&self) -> Result<()> {
        let Some((limit, source)) = memory_limit()? else {
            return Ok(());
        };
        #[allow(clippy::cast_precision_loss)]
        if self.bytes > limit as f64 {
            return Err(Error::OutOfMemory(format!(
                "the model has {} nodes, {} elements and {} DOFs; its tangent would hold about {:.2e} entries and \
                 its sparse factor about {:.2e}: the analysis needs about {}, more than {} ({source}). Use a \
                 coarser mesh, or set the environment variable {LIMIT_VARIABLE} (e.g. '32G', or 'none') to \
                 try anyway",
                self.nodes,
                self.elements,
                self.dofs,
                self.matrix_entries,
                self.factor_entries,
                human(self.bytes),
                human(limit as f64),
            )));
        }
        Ok(())
    }
}

/// Checks the exact size of a factor (`factor_entries` entries, plus `workspace` bytes) of a
/// matrix of `n` rows and `matrix_entries` entries against [`memory_limit`], before its values
/// are allocated.
///
/// # Errors
/// As [`MemoryEstimate::check`].
#[allow(clippy::cast_precision_loss)]
pub fn check_factor(n: usize, matrix_entries: usize, factor_entries: usize, workspace: usize) -> Result<()> {
    let Some((limit, source)) = memory_limit()? else {
        return Ok(());
    };
    let bytes = BYTES_PER_FACTOR_ENTRY * factor_entries as f64 + workspace as f64;
    if bytes > limit as f64 {
        return Err(Error::OutOfMemory(format!(
            "the sparse factor of the tangent ({n} free DOFs, {matrix_entries} entries) has {factor_entries} entries: \
             it needs about {}, more than {} ({source}). Use a coarser mesh, or set the environment variable \
             {LIMIT_VARIABLE} (e.g. '32G', or 'none') to try anyway",
            human(bytes),
            human(limit as f64),
        )));
    }
    Ok(())
}

/// Checks that a mesh of `nodes` nodes and `elements` quadrilaterals (`None`: more than `usize`
/// holds) can be held in memory: coordinates and connectivity, three times (the generator's, the
/// numpy arrays, the model's).
///
/// # Errors
/// [`Error::OutOfMemory`] naming the sizes, as [`MemoryEstimate::check`].
#[allow(clippy::cast_precision_loss)]
pub fn check_mesh(nodes: Option<usize>, elements: Option<usize>) -> Result<()> {
    let (Some(nodes), Some(elements)) = (nodes, elements) else {
        return Err(Error::OutOfMemory(
            "the mesh would have more elements than this machine can even count".into(),
        ));
    };
    let Some((limit, source)) = memory_limit()? else {
        return Ok(());
    };
    let bytes = 3.0 * (24.0 * nodes as f64 + 32.0 * elements as f64);
    if bytes > limit as f64 {
        return Err(Error::OutOfMemory(format!(
            "a mesh of {nodes} nodes and {elements} elements needs about {} to hold, more than {} \
             ({source}); use fewer elements, or set the environment variable {LIMIT_VARIABLE} \
             (e.g. '32G', or 'none') to try anyway",
            human(bytes),
            human(limit as f64),
        )));
    }
    Ok(())
}

/// Bytes as a human-readable size ("3.2 GB").
fn human(bytes: f64) -> String {
    const UNITS: [&str; 5] = ["B", "kB", "MB", "GB", "TB"];
    let mut v = bytes;
    let mut u = 0;
    while v >= 1000.0 && u + 1 < UNITS.len() {
        v /= 1000.0;
        u += 1;
    }
    format!("{v:.1} {}", UNITS[u])
}

/// The memory limit \[bytes\] and where it comes from; `None` if the check is disabled
/// (`TAPESPRING_MEMORY_LIMIT=none`).
///
/// # Errors
/// [`Error::InvalidParameter`] if `TAPESPRING_MEMORY_LIMIT` is set but is not a size.
pub fn memory_limit() -> Result<Option<(u64, String)>> {
    if let Ok(text) = std::env::var(LIMIT_VARIABLE) {
        return parse_limit(&text).map(|l| l.map(|b| (b, format!("the limit {LIMIT_VARIABLE}={text}"))));
    }
    Ok(Some(match available_memory() {
        Some(b) => (b, "the memory available on this machine".to_owned()),
        None => (
            FALLBACK_LIMIT,
            "the default limit where available memory is unknown".to_owned(),
        ),
    }))
}

/// Parses a size: bytes, or a number with a unit K, M, G or T (powers of 1024; an optional
/// trailing `B` or `iB`); `none`, `off` or `unlimited` disable the check.
fn parse_limit(text: &str) -> Result<Option<u64>> {
    let t = text.trim();
    if ["none", "off", "unlimited"]
        .iter()
        .any(|w| t.eq_ignore_ascii_case(w))
    {
        return Ok(None);
    }
    let bad = || {
        Error::InvalidParameter(format!(
            "{LIMIT_VARIABLE} = '{text}' is not a memory size (bytes, or a number with K, M, G or T, e.g. '16G'; 'none' \
             disables the check)"
        ))
    };
    let upper = t.to_ascii_uppercase();
    let body = upper
        .strip_suffix("IB")
        .or_else(|| upper.strip_suffix('B'))
        .unwrap_or(&upper);
    let (number, scale) = match body.chars().last() {
        Some('K') => (&body[..body.len() - 1], 1u64 << 10),
        Some('M') => (&body[..body.len() - 1], 1 << 20),
        Some('G') => (&body[..body.len() - 1], 1 << 30),
        Some('T') => (&body[..body.len() - 1], 1 << 40),
        _ => (body, 1),
    };
    let value: f64 = number.trim().parse().map_err(|_| bad())?;
    if !(value.is_finite() && value > 0.0) {
        return Err(bad());
    }
    #[allow(
        clippy::cast_possible_truncation,
        clippy::cast_sign_loss,
        clippy::cast_precision_loss
    )]
    Ok(Some((value * scale as f64).min(u64::MAX as f64) as u64))
}

/// Memory available to this process \[bytes\]: `MemAvailable` of `/proc/meminfo`, and the room
/// left under the cgroup's limit (`memory.max - memory.current`, cgroup v2) if smaller; `None`
/// where neither can be read.
#[must_use]
pub fn available_memory() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|text| {
            text.lines()
                .find_map(|l| l.strip_prefix("MemAvailable:"))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
                .map(|kb| kb.saturating_mul(1024))
        });
    let read = |p: &str| {
        std::fs::read_to_string(p)
            .ok()
            .and_then(|s| s.trim().parse::<u64>().ok())
    };
    let cgroup = match (read("/sys/fs/cgroup/memory.max"), read("/sys/fs/cgroup/memory.current")) {
        (Some(max), Some(current)) => Some(max.saturating_sub(current)),
        _ => None,
    };
    match (meminfo, cgroup) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_parse_with_units_and_refuse_garbage() {
        assert_eq!(parse_limit("1024").unwrap(), Some(1024));
        assert_eq!(parse_limit("2K").unwrap(), Some(2048));
        assert_eq!(parse_limit(" 1.5 GiB ").unwrap(), Some(3 << 29));
        assert_eq!(parse_limit("16g").unwrap(), Some(16 << 30));
        assert_eq!(parse_limit("none").unwrap(), None);
        for bad in ["", "abc", "-1G", "0", "nanG", "1X"] {
            let err = parse_limit(bad).unwrap_err().to_string();
            assert!(err.contains(LIMIT_VARIABLE), "{bad}: {err}");
        }
    }

    #[test]
    fn estimate_grows_with_the_mesh_and_names_the_sizes() {
        let small = MemoryEstimate::of_mesh(561, 500);
        let big = MemoryEstimate::of_mesh(4_000_000, 3_990_000);
        assert!(small.bytes < 50e6, "{small:?}");
        assert!(big.bytes > 20e9, "{big:?}");
        assert!(available_memory().is_none_or(|b| b > 0));
    }
}
