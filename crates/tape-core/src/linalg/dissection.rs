//! A separator found from the matrix graph alone: the top level of a nested dissection.
//!
//! A single tape spring has no rigid tie that splits it, so the bordered factorisation needs a
//! separator from the graph. The level structure of a breadth-first search from a
//! pseudo-peripheral unknown (George & Liu, "Computer Solution of Large Sparse Positive Definite
//! Systems", 1981, sec. 4.3) cuts a strip-like shell mesh into cross-sections: any level splits
//! the unknowns before it from those after it, since an edge joins only the same or adjacent
//! levels. The thinnest level near the middle is the separator.

use super::Pattern;

/// Share of the unknowns that must lie on each side of the chosen level.
const MIN_SIDE: f64 = 0.35;

/// Fewest unknowns worth splitting. Measured on the tape spring (criterion, `numeric
/// factorisation`): 218 DOFs took 38 us split against 31 us whole, 482 DOFs 91 against 104 us,
/// 1010 DOFs 196 against 270 us.
const MIN_UNKNOWNS: usize = 400;

/// Breadth-first levels from `root` over the unknowns `seen` leaves open (marked as they are
/// reached); the unknowns level by level, and where each level starts.
fn levels(pattern: &Pattern, root: usize, seen: &mut [bool]) -> (Vec<usize>, Vec<usize>) {
    let mut order = vec![root];
    let mut starts = vec![0];
    seen[root] = true;
    let mut head = 0;
    while head < order.len() {
        starts.push(order.len());
        let end = order.len();
        while head < end {
            let j = order[head];
            head += 1;
            for &i in &pattern.row_idx[pattern.col_ptr[j]..pattern.col_ptr[j + 1]] {
                if !seen[i] {
                    seen[i] = true;
                    order.push(i);
                }
            }
        }
    }
    starts.dedup();
    (order, starts)
}

fn degree(pattern: &Pattern, j: usize) -> usize {
    pattern.col_ptr[j + 1] - pattern.col_ptr[j]
}

/// The level structure of the largest connected component, rooted at a pseudo-peripheral
/// unknown: from the unknown of least degree, the search restarts from the last level's unknown
/// of least degree while that lengthens the structure.
fn rooted_levels(pattern: &Pattern) -> Option<(Vec<usize>, Vec<usize>)> {
    let n = pattern.nrows;
    // The largest component, and its unknown of least degree.
    let mut seen = vec![false; n];
    let mut best: Option<(usize, usize)> = None;
    for seed in 0..n {
        if seen[seed] {
            continue;
        }
        let (order, _) = levels(pattern, seed, &mut seen);
        if best.is_none_or(|(size, _)| order.len() > size) {
            let root = *order.iter().min_by_key(|&&j| (degree(pattern, j), j))?;
            best = Some((order.len(), root));
        }
    }
    let (_, root) = best?;
    let mut current = levels(pattern, root, &mut vec![false; n]);
    // The depth grows at each accepted restart, so the loop ends within n restarts.
    loop {
        let (order, starts) = &current;
        let last = &order[starts[starts.len() - 2]..];
        let candidate = *last.iter().min_by_key(|&&j| (degree(pattern, j), j))?;
        let next = levels(pattern, candidate, &mut vec![false; n]);
        if next.1.len() <= starts.len() {
            return Some(current);
        }
        current = next;
    }
}

/// A separator of the graph of `pattern` (structurally symmetric): the thinnest level of the
/// rooted level structure with at least 35 % of the largest component's unknowns on each side,
/// less the unknowns with no neighbour in the next level (they can join the first side). Empty
/// when no level qualifies (a component too shallow to cut) or the graph is too small for the
/// split to pay (`MIN_UNKNOWNS`).
pub(super) fn level_separator(pattern: &Pattern) -> Vec<usize> {
    if pattern.nrows < MIN_UNKNOWNS {
        return Vec::new();
    }
    let Some((order, starts)) = rooted_levels(pattern) else {
        return Vec::new();
    };
    let size = order.len() as f64;
    let n_levels = starts.len() - 1;
    let chosen = (1..n_levels.saturating_sub(1))
        .filter(|&k| {
            let before = starts[k] as f64;
            let after = size - starts[k + 1] as f64;
            before >= MIN_SIDE * size && after >= MIN_SIDE * size
        })
        .min_by_key(|&k| {
            (
                starts[k + 1] - starts[k],
                starts[k].abs_diff(order.len() - starts[k + 1]),
                k,
            )
        });
    let Some(k) = chosen else {
        return Vec::new();
    };
    let mut level_of = vec![usize::MAX; pattern.nrows];
    for (l, w) in starts.windows(2).enumerate() {
        for &j in &order[w[0]..w[1]] {
            level_of[j] = l;
        }
    }
    let mut sep: Vec<usize> = order[starts[k]..starts[k + 1]]
        .iter()
        .copied()
        .filter(|&j| {
            pattern.row_idx[pattern.col_ptr[j]..pattern.col_ptr[j + 1]]
                .iter()
                .any(|&i| level_of[i] == k + 1)
        })
        .collect();
    sep.sort_unstable();
    sep
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The graph of a grid of `nx` x `ny` nodes with `dofs` unknowns each, the nodes of each
    /// cell coupled (a quadrilateral shell mesh's pattern).
    fn grid(nx: usize, ny: usize, dofs: usize) -> Pattern {
        let node = |i: usize, j: usize| i * ny + j;
        let mut cols = vec![Vec::new(); nx * ny * dofs];
        for i in 0..nx - 1 {
            for j in 0..ny - 1 {
                let cell = [node(i, j), node(i + 1, j), node(i, j + 1), node(i + 1, j + 1)];
                for &a in &cell {
                    for &b in &cell {
                        for da in 0..dofs {
                            for db in 0..dofs {
                                cols[a * dofs + da].push(b * dofs + db);
                            }
                        }
                    }
                }
            }
        }
        Pattern::from_columns(nx * ny * dofs, cols)
    }

    /// Unknowns not in `sep`, grouped by the components left once `sep` is removed.
    fn sides(pattern: &Pattern, sep: &[usize]) -> Vec<usize> {
        let mut seen = vec![false; pattern.nrows];
        for &s in sep {
            seen[s] = true;
        }
        let mut sizes = Vec::new();
        for seed in 0..pattern.nrows {
            if !seen[seed] {
                sizes.push(levels(pattern, seed, &mut seen).0.len());
            }
        }
        sizes.sort_unstable();
        sizes
    }

    /// On a strip (a tape's mesh) the separator is one cross-section of nodes, all their
    /// unknowns, and it cuts the strip near its middle.
    #[test]
    fn a_strip_is_cut_across_near_its_middle() {
        let (nx, ny, dofs) = (60, 8, 6);
        let pattern = grid(nx, ny, dofs);
        let sep = level_separator(&pattern);
        assert_eq!(sep.len(), ny * dofs, "separator {sep:?}");
        let sides = sides(&pattern, &sep);
        assert_eq!(sides.len(), 2);
        let n = (nx * ny * dofs) as f64;
        assert!(sides.iter().all(|&s| s as f64 >= MIN_SIDE * n), "{sides:?}");
    }

    /// A square grid is cut into two sides, around a corner: from a corner the levels are the
    /// L-shaped rings of equal Chebyshev distance (the cells couple their diagonals), the
    /// thinnest one with 35 % of the 400 nodes inside is the ring at distance 12 (25 nodes).
    /// No separator for a graph too shallow to cut (one cell of 200 unknowns per node, all
    /// coupled), one below `MIN_UNKNOWNS` (a strip of 360) or an empty one.
    #[test]
    fn squares_are_cut_and_small_or_shallow_graphs_are_not() {
        let pattern = grid(20, 20, 1);
        let sep = level_separator(&pattern);
        assert_eq!(sep.len(), 25);
        let sides = sides(&pattern, &sep);
        assert_eq!(sides.len(), 2, "{sides:?}");
        assert!(level_separator(&grid(2, 2, 200)).is_empty());
        assert!(level_separator(&grid(30, 2, 6)).is_empty());
        assert!(!level_separator(&grid(34, 2, 6)).is_empty());
        assert!(level_separator(&Pattern::default()).is_empty());
    }

    /// Two unconnected strips: the larger one is cut, the smaller stays whole.
    #[test]
    fn the_largest_component_is_cut() {
        let a = grid(40, 4, 3);
        let b = grid(10, 4, 3);
        let na = a.nrows;
        let mut cols: Vec<Vec<usize>> = (0..na)
            .map(|j| a.row_idx[a.col_ptr[j]..a.col_ptr[j + 1]].to_vec())
            .collect();
        cols.extend((0..b.nrows).map(|j| {
            b.row_idx[b.col_ptr[j]..b.col_ptr[j + 1]]
                .iter()
                .map(|i| i + na)
                .collect()
        }));
        let pattern = Pattern::from_columns(na + b.nrows, cols);
        let sep = level_separator(&pattern);
        assert_eq!(sep.len(), 4 * 3);
        assert!(sep.iter().all(|&s| s < na));
        assert_eq!(sides(&pattern, &sep).len(), 3);
    }
}
