//! Relabelling (SPEC §3.6): give each chosen episode the label of the skill that explains it
//! best, either jointly by a minimum-cost assignment that keeps the multiset of labels, or
//! independently by the maximum.

pub use seads_run::RelabelKind;

/// New labels by assignment (SPEC §3.6): slot i carries label `labels[i]`, column j is episode j,
/// the cost of giving episode j label `labels[i]` is `−C_j[labels[i]]`; a minimum-cost assignment
/// says which episode receives which label. `clipped` holds the K clipped log-posteriors of each
/// episode, row-major. The multiset of labels is preserved.
///
/// The reference solves this as a square n × n problem (SciPy's `linear_sum_assignment`), cubic
/// in the number of episodes. Slots with the same label are interchangeable, so it is a
/// transportation problem: the distinct labels are sources whose capacities are their counts.
/// It is solved by successive shortest paths (below), with the same optimal total; where several
/// assignments are optimal, ties may break differently from SciPy's.
pub fn relabel_assignment(clipped: &[f32], k: usize, labels: &[usize]) -> Vec<usize> {
    // The distinct labels, ascending, and how many slots carry each.
    let mut groups: Vec<usize> = labels.to_vec();
    groups.sort_unstable();
    groups.dedup();
    let capacity: Vec<usize> = groups
        .iter()
        .map(|g| labels.iter().filter(|l| *l == g).count())
        .collect();
    let cost: Vec<Vec<f64>> = (0..labels.len())
        .map(|e| {
            groups
                .iter()
                .map(|&g| -f64::from(clipped[e * k + g]))
                .collect()
        })
        .collect();
    capacitated_assignment(&cost, &capacity)
        .into_iter()
        .map(|g| groups[g])
        .collect()
}

/// A minimum-cost assignment of episodes to groups that takes exactly `capacity[g]` episodes
/// into group g (the capacities add up to the number of episodes). `cost[e][g]` is the cost of
/// putting episode e into group g. Returns each episode's group.
///
/// Episodes are added one at a time, each along a shortest augmenting path, which keeps the
/// partial assignment optimal (the successive-shortest-path method for min-cost flow). A path
/// enters a group and, if that group is full, moves one of its episodes on to another group: with
/// G groups the paths live on a G-node graph whose edge g → h costs the cheapest such move. The
/// partial assignment is optimal, so that graph has no negative cycle and Bellman–Ford finds the
/// paths. An episode costs O(G³) for the paths plus O(n/G·G) per group whose members changed
/// (those on the path): for n = 512 episodes and G ≤ 30 labels, about a millisecond, where the
/// square problem costs O(n³).
fn capacitated_assignment(cost: &[Vec<f64>], capacity: &[usize]) -> Vec<usize> {
    const NONE: usize = usize::MAX;
    let g_count = capacity.len();
    let mut group_of = vec![NONE; cost.len()];
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); g_count];
    // Cheapest move out of each group into each other group, and the episode that makes it.
    // Only the groups on the last path changed, so only their rows are recomputed.
    let mut edge = vec![(f64::INFINITY, NONE); g_count * g_count];
    let mut dist = vec![0.0f64; g_count];
    let mut pred = vec![NONE; g_count];
    let mut changed_groups: Vec<usize> = Vec::new();
    for new in 0..cost.len() {
        for &g in &changed_groups {
            let row = &mut edge[g * g_count..(g + 1) * g_count];
            row.fill((f64::INFINITY, NONE));
            for &e in &members[g] {
                for (h, slot) in row.iter_mut().enumerate() {
                    let step = cost[e][h] - cost[e][g];
                    if h != g && step < slot.0 {
                        *slot = (step, e);
                    }
                }
            }
        }
        changed_groups.clear();
        // Shortest paths from the new episode (it enters group h at cost[new][h]).
        dist.copy_from_slice(&cost[new]);
        pred.fill(NONE);
        for _ in 0..g_count {
            let mut changed = false;
            for g in 0..g_count {
                // Only a full group passes an episode on; a group with room ends the path.
                if members[g].len() < capacity[g] {
                    continue;
                }
                for h in 0..g_count {
                    let (step, _) = edge[g * g_count + h];
                    if dist[g] + step < dist[h] {
                        dist[h] = dist[g] + step;
                        pred[h] = g;
                        changed = true;
                    }
                }
            }
            if !changed {
                break;
            }
        }
        // The cheapest group with room (the first on ties).
        let mut target = NONE;
        for g in 0..g_count {
            if members[g].len() < capacity[g] && (target == NONE || dist[g] < dist[target]) {
                target = g;
            }
        }
        // Walk the path back: each group on it hands one episode to the next.
        let mut h = target;
        while pred[h] != NONE {
            let g = pred[h];
            let moved = edge[g * g_count + h].1;
            members[g].retain(|&e| e != moved);
            members[h].push(moved);
            group_of[moved] = h;
            changed_groups.extend([g, h]);
            h = g;
        }
        members[h].push(new);
        group_of[new] = h;
        changed_groups.push(h);
        changed_groups.sort_unstable();
        changed_groups.dedup();
    }
    group_of
}

/// New labels by independent maximisation: `argmax_k C_e[k]` (first maximum on ties).
///
/// ```
/// use seads_skillmodel::relabel_max;
/// // Two episodes of K = 3: the second ties skills 0 and 2 and takes the first.
/// let clipped = [-2.0, -0.1, -3.0, /* episode 1: */ -0.5, -2.0, -0.5];
/// assert_eq!(relabel_max(&clipped, 3), vec![1, 0]);
/// ```
pub fn relabel_max(clipped: &[f32], k: usize) -> Vec<usize> {
    clipped
        .chunks(k)
        .map(|c| {
            c.iter()
                .enumerate()
                .fold(0, |best, (i, &v)| if v > c[best] { i } else { best })
        })
        .collect()
}

/// Relabels by `kind`.
pub fn relabel(kind: RelabelKind, clipped: &[f32], k: usize, labels: &[usize]) -> Vec<usize> {
    match kind {
        RelabelKind::Assignment => relabel_assignment(clipped, k, labels),
        RelabelKind::Max => relabel_max(clipped, k),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn assignment_swaps_labels_to_the_episodes_they_explain() {
        // Episode 0 looks like skill 2, episode 1 like skill 0, episode 2 like skill 1.
        let k = 3;
        let clipped = [
            -5.0, -5.0, -0.1, //
            -0.1, -5.0, -5.0, //
            -5.0, -0.1, -5.0,
        ];
        assert_eq!(relabel_assignment(&clipped, k, &[0, 1, 2]), vec![2, 0, 1]);
        // With labels {0, 0, 1} only one episode can keep label 1: the one it explains best.
        assert_eq!(relabel_assignment(&clipped, k, &[0, 0, 1]), vec![0, 0, 1]);
        assert_eq!(relabel_max(&clipped, k), vec![2, 0, 1]);
    }
}
