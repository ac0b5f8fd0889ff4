//! Relabelling (SPEC §3.6): give each chosen episode the label of the skill that explains it
//! best, either jointly by a minimum-cost assignment that keeps the multiset of labels, or
//! independently by the maximum.

use serde::{Deserialize, Serialize};

/// How chosen episodes are relabelled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RelabelKind {
    /// One linear assignment over all chosen episodes (SEADS).
    Assignment,
    /// Each episode independently gets argmax_k C_e[k] (not used in the paper).
    Max,
}

/// New labels by assignment: slot i carries label `labels[i]`, column j is episode j, the cost of
/// giving episode j label `labels[i]` is −C_j[labels[i]]; the minimum-cost assignment (SciPy's
/// algorithm, as the reference) says which episode receives which label. `clipped` holds the K
/// clipped log-posteriors of each episode, row-major. The multiset of labels is preserved.
pub fn relabel_assignment(clipped: &[f32], k: usize, labels: &[usize]) -> Vec<usize> {
    let n = labels.len();
    if n == 0 {
        return Vec::new();
    }
    let mut cost = vec![0.0f64; n * n];
    for (i, &label) in labels.iter().enumerate() {
        for j in 0..n {
            cost[i * n + j] = -(clipped[j * k + label] as f64);
        }
    }
    let (rows, cols) = lsap::solve(n, n, &cost, false).expect("finite costs have an assignment");
    let mut new_labels = vec![0; n];
    for (&slot, &episode) in rows.iter().zip(&cols) {
        new_labels[episode] = labels[slot];
    }
    new_labels
}

/// New labels by independent maximisation: argmax_k C_e[k] (first maximum on ties).
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
