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
/// when no level qualifies (a component too shallow to cut) or the largest component is too
/// small for the split to pay (`MIN_UNKNOWNS`; the rest of the graph is not split either way).
pub(super) fn level_separator(pattern: &Pattern) -> Vec<usize> {
    if pattern.nrows < MIN_UNKNOWNS {
        return Vec::new();
    }
    let Some((order, starts)) = rooted_levels(pattern) else {
        return Vec::new();
    };
    if order.len() < MIN_UNKNOWNS {
        return Vec::new();
    }
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

    /// An open [`tube`]: a quadrilateral shell mesh's pattern.
    fn grid(nx: usize, ny: usize, dofs: usize) -> Pattern {
        tube(nx, ny, dofs, false)
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
    /// coupled), one whose largest component is below `MIN_UNKNOWNS` (a strip of 360, alone or
    /// beside isolated unknowns) or an empty one.
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
        // The bound is on the component cut, not on the whole graph: the strip of 360 with 100
        // isolated unknowns beside it stays whole.
        let (with_isolated, _) = shuffled_union(&[grid(30, 2, 6)], 100, &mut Rng(7));
        assert!(with_isolated.nrows >= MIN_UNKNOWNS);
        assert!(level_separator(&with_isolated).is_empty());
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

    /// Deterministic pseudo-random integers below `m` (xorshift).
    struct Rng(u64);
    impl Rng {
        fn below(&mut self, m: usize) -> usize {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            usize::try_from(self.0 % m as u64).expect("below m")
        }
    }

    /// The graph of a grid of `nx` x `ny` nodes with `dofs` unknowns each, the nodes of each
    /// cell coupled, closed into a tube when `closed` (the cells of the last row of nodes couple
    /// it to the first: a cylinder's mesh).
    fn tube(nx: usize, ny: usize, dofs: usize, closed: bool) -> Pattern {
        let node = |i: usize, j: usize| i * ny + j % ny;
        let mut cols = vec![Vec::new(); nx * ny * dofs];
        let rows = if closed { ny } else { ny - 1 };
        for i in 0..nx - 1 {
            for j in 0..rows {
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

    /// The graphs of `parts` side by side (unconnected), then `isolated` unknowns with their
    /// diagonal only, all renumbered by a random permutation; and the new label of each old one.
    fn shuffled_union(parts: &[Pattern], isolated: usize, rng: &mut Rng) -> (Pattern, Vec<usize>) {
        let n = parts.iter().map(|p| p.nrows).sum::<usize>() + isolated;
        let mut label: Vec<usize> = (0..n).collect();
        for i in (1..n).rev() {
            label.swap(i, rng.below(i + 1));
        }
        let mut cols = vec![Vec::new(); n];
        let mut offset = 0;
        for p in parts {
            for j in 0..p.nrows {
                cols[label[offset + j]] = p.row_idx[p.col_ptr[j]..p.col_ptr[j + 1]]
                    .iter()
                    .map(|&i| label[offset + i])
                    .collect();
            }
            offset += p.nrows;
        }
        for j in offset..n {
            cols[label[j]] = vec![label[j]];
        }
        (Pattern::from_columns(n, cols), label)
    }

    /// The component of each unknown once the unknowns `removed` are taken out (`usize::MAX`
    /// for those), by a depth-first search independent of `levels`; and the components' sizes.
    fn component_labels(pattern: &Pattern, removed: &[usize]) -> (Vec<usize>, Vec<usize>) {
        let mut label = vec![usize::MAX; pattern.nrows];
        let mut out = vec![false; pattern.nrows];
        for &s in removed {
            out[s] = true;
        }
        let mut sizes = Vec::new();
        for seed in 0..pattern.nrows {
            if out[seed] || label[seed] != usize::MAX {
                continue;
            }
            let c = sizes.len();
            let (mut stack, mut size) = (vec![seed], 0);
            label[seed] = c;
            while let Some(j) = stack.pop() {
                size += 1;
                for &i in &pattern.row_idx[pattern.col_ptr[j]..pattern.col_ptr[j + 1]] {
                    if !out[i] && label[i] == usize::MAX {
                        label[i] = c;
                        stack.push(i);
                    }
                }
            }
            sizes.push(size);
        }
        (label, sizes)
    }

    /// Checks what `level_separator` promises of a non-empty separator: sorted and distinct, all
    /// in one largest component, which it cuts into pieces with at least `MIN_SIDE` of the
    /// component on each side (so no piece above `1 - MIN_SIDE` less the separator, and the
    /// pieces other than the largest at least `MIN_SIDE`), every separator unknown touching two
    /// pieces (none is superfluous). Returns the size of the component cut.
    #[allow(clippy::cast_precision_loss)]
    fn check_split(pattern: &Pattern, sep: &[usize]) -> usize {
        assert!(sep.windows(2).all(|w| w[0] < w[1]), "separator not sorted: {sep:?}");
        assert!(sep.iter().all(|&s| s < pattern.nrows));
        let (whole, whole_sizes) = component_labels(pattern, &[]);
        let largest = whole_sizes.iter().copied().max().expect("a component");
        let c = whole[sep[0]];
        assert!(sep.iter().all(|&s| whole[s] == c), "the separator spans components");
        assert_eq!(whole_sizes[c], largest, "the separator is not in a largest component");
        let (cut, cut_sizes) = component_labels(pattern, sep);
        let mut pieces: Vec<usize> = (0..pattern.nrows)
            .filter(|&j| whole[j] == c && cut[j] != usize::MAX)
            .map(|j| cut[j])
            .collect();
        pieces.sort_unstable();
        pieces.dedup();
        assert!(pieces.len() >= 2, "the separator does not split its component");
        let sizes: Vec<usize> = pieces.iter().map(|&p| cut_sizes[p]).collect();
        let biggest = *sizes.iter().max().expect("pieces");
        let rest = largest - sep.len() - biggest;
        let min_side = MIN_SIDE * largest as f64;
        assert!(
            rest as f64 >= min_side && biggest as f64 <= (largest - sep.len()) as f64 - min_side,
            "pieces {sizes:?} of a component of {largest} less {} separator unknowns",
            sep.len()
        );
        for &s in sep {
            let mut touched: Vec<usize> = pattern.row_idx[pattern.col_ptr[s]..pattern.col_ptr[s + 1]]
                .iter()
                .map(|&i| cut[i])
                .filter(|&p| p != usize::MAX)
                .collect();
            touched.sort_unstable();
            touched.dedup();
            assert!(touched.len() >= 2, "separator unknown {s} touches pieces {touched:?}");
        }
        largest
    }

    /// Property test over random strips, grids and tubes (closed cross-sections), with 1 to 6
    /// unknowns per node, shuffled numberings, sometimes a second unconnected part and isolated
    /// unknowns (diagonal only): every separator found splits a largest component as promised
    /// (`check_split`); on a strip at least three times as long as wide and 12 nodes long, the
    /// largest component and 400 unknowns or more, it is found and is one cross-section of nodes.
    #[test]
    fn level_separator_splits_shuffled_strips_grids_and_tubes() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let (mut cut, mut cross_sections) = (0, 0);
        for trial in 0..400 {
            let closed = trial % 4 == 3;
            let ny = if closed { 3 + rng.below(10) } else { 2 + rng.below(11) };
            let nx = 2 + rng.below(70);
            let dofs = [1, 2, 3, 6][rng.below(4)];
            let mut parts = vec![tube(nx, ny, dofs, closed)];
            if trial % 5 == 0 {
                parts.push(grid(2 + rng.below(30), 2 + rng.below(4), dofs));
            }
            let isolated = if trial % 3 == 0 { rng.below(300) } else { 0 };
            let (pattern, label) = shuffled_union(&parts, isolated, &mut rng);
            let sep = level_separator(&pattern);
            let strip = parts[0].nrows;
            let strip_is_largest = parts.iter().skip(1).all(|p| p.nrows < strip) && strip > 1;
            let long = nx >= 12 && nx >= 3 * ny;
            if sep.is_empty() {
                assert!(
                    !(long && strip_is_largest && strip >= MIN_UNKNOWNS),
                    "no separator for a {nx} x {ny} strip of {dofs} unknowns per node (closed: {closed})"
                );
                continue;
            }
            cut += 1;
            let size = check_split(&pattern, &sep);
            assert!(size >= MIN_UNKNOWNS, "a component of {size} unknowns was split");
            if long && strip_is_largest {
                assert_eq!(size, strip);
                // The separator is whole nodes of the strip (its first part's labels).
                let mut old = vec![usize::MAX; pattern.nrows];
                for (o, &j) in label.iter().enumerate() {
                    old[j] = o;
                }
                for &s in &sep {
                    let node = old[s] / dofs;
                    assert!(old[s] < strip, "separator unknown {s} outside the strip");
                    assert!((0..dofs).all(|d| sep.binary_search(&label[node * dofs + d]).is_ok()));
                }
                assert_eq!(sep.len(), ny * dofs, "{nx} x {ny} x {dofs} (closed: {closed})");
                cross_sections += 1;
            }
        }
        assert!(
            cut > 100 && cross_sections > 50,
            "{cut} graphs cut, {cross_sections} strips"
        );
    }

    /// Graphs with nothing to cut: isolated unknowns only, columns with no entry at all (not even
    /// the diagonal), a clique larger than the strip beside it; none panics and none is cut. A
    /// path (a tridiagonal matrix) and a ring are cut at one and two unknowns, near the middle. A
    /// comb (a path with one pendant unknown on each of its unknowns) from a pendant: each level
    /// is a path unknown and the previous one's pendant, which has no neighbour in the next level
    /// and is dropped (the refinement), leaving one unknown that still splits the comb.
    #[test]
    fn degenerate_graphs_are_cut_only_where_they_split() {
        let diagonal = Pattern::from_columns(500, (0..500).map(|j| vec![j]).collect());
        assert!(level_separator(&diagonal).is_empty());
        let empty = Pattern::from_columns(500, vec![Vec::new(); 500]);
        assert!(level_separator(&empty).is_empty());
        let mut rng = Rng(7);
        let (clique_and_strip, _) = shuffled_union(&[grid(2, 2, 120), grid(20, 2, 6)], 10, &mut rng);
        assert!(level_separator(&clique_and_strip).is_empty());
        for n in [400, 1001, 5000] {
            let path = Pattern::from_columns(
                n,
                (0..n)
                    .map(|j| (j.saturating_sub(1)..(j + 2).min(n)).collect())
                    .collect(),
            );
            let sep = level_separator(&path);
            assert_eq!(sep.len(), 1, "path of {n}: {sep:?}");
            check_split(&path, &sep);
            let ring = Pattern::from_columns(
                n,
                (0..n)
                    .map(|j| vec![(j + n - 1) % n, j, (j + 1) % n])
                    .collect(),
            );
            let sep = level_separator(&ring);
            assert_eq!(sep.len(), 2, "ring of {n}: {sep:?}");
            check_split(&ring, &sep);
            let comb = Pattern::from_columns(
                2 * n,
                (0..2 * n)
                    .map(|j| match j.checked_sub(n) {
                        None => (j.saturating_sub(1)..(j + 2).min(n))
                            .chain([n + j])
                            .collect(),
                        Some(i) => vec![i, j],
                    })
                    .collect(),
            );
            let sep = level_separator(&comb);
            assert_eq!(sep.len(), 1, "comb of {n}: {sep:?}");
            assert!(sep[0] < n, "comb of {n}: a pendant in the separator");
            check_split(&comb, &sep);
        }
    }
}
