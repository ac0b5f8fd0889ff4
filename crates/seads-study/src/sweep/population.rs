//! Populations of a sweep: its runs grouped by what their networks' shapes depend on
//! ([`seads_run::PopulationKey`]), each group cut into populations of at most K runs that one task
//! trains together (`seads sweep run --population K`, and one Slurm array task per population).

use std::path::Path;

use seads_run::PopulationKey;

use super::index::Sweep;
use crate::Result;
use crate::error::fail;

/// The runs `indices` of the sweep in `dir` as populations of at most `k`: runs with equal
/// [`PopulationKey`]s together, in the order the indices come, each population's members in
/// that order too. A run whose config cannot be read is a population of its own (its task
/// says why it fails). `k = 0` is an error.
pub fn populations(
    dir: &Path,
    sweep: &Sweep,
    indices: &[usize],
    k: usize,
) -> Result<Vec<Vec<usize>>> {
    if k == 0 {
        fail!("--population must be at least 1");
    }
    let keys: Vec<Option<PopulationKey>> = indices
        .iter()
        .map(|&i| {
            let run = dir.join(&sweep.runs.get(i)?.dir);
            seads_run::load_config(&run)
                .ok()
                .map(|c| PopulationKey::of(&c))
        })
        .collect();
    Ok(group(indices, &keys, k))
}

/// Groups `indices` by `keys` (`None`: alone), first appearance first, cut into chunks of `k`.
fn group<K: PartialEq>(indices: &[usize], keys: &[Option<K>], k: usize) -> Vec<Vec<usize>> {
    let mut groups: Vec<(Option<&K>, Vec<usize>)> = Vec::new();
    for (&index, key) in indices.iter().zip(keys) {
        match groups
            .iter_mut()
            .find(|(g, _)| key.is_some() && g.is_some() && *g == key.as_ref())
        {
            Some((_, members)) => members.push(index),
            None => groups.push((key.as_ref(), vec![index])),
        }
    }
    groups
        .into_iter()
        .flat_map(|(_, members)| {
            members
                .chunks(k.max(1))
                .map(<[usize]>::to_vec)
                .collect::<Vec<_>>()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::group;

    #[test]
    fn runs_group_by_key_in_order_and_in_chunks_of_k() {
        let keys = [
            Some('a'),
            Some('b'),
            Some('a'),
            None,
            Some('a'),
            Some('b'),
            None,
        ];
        let indices: Vec<usize> = (10..17).collect();
        // Chunks of 2: a = 10, 12, 14 -> [10, 12], [14]; b = 11, 15; the unreadable alone.
        assert_eq!(
            group(&indices, &keys, 2),
            vec![vec![10, 12], vec![14], vec![11, 15], vec![13], vec![16]]
        );
        assert_eq!(
            group(&indices, &keys, 8),
            vec![vec![10, 12, 14], vec![11, 15], vec![13], vec![16]]
        );
        assert_eq!(group(&indices, &keys, 1).len(), 7);
    }
}
