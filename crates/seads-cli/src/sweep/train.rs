//! Training a population of a sweep's runs ([`seads_rl::Population`],
//! [`seads_rl::StackedPopulation`]): each member's
//! provenance, one crash-point hook over all members, and every member's evaluations handed to
//! the caller as they are written.

use std::sync::{Arc, Mutex};

use seads_rl::{
    BoxError, ComputeDevice, Hook, InWords, Learner, Members, RlError, Run, TrainConfig,
};

use seads_study::provenance::Build;

/// A member's configuration for this process: its networks on `device`, one libtorch thread
/// (the members' epochs fill the cores side by side). Neither changes a number on the CPU.
pub fn member_config(mut config: TrainConfig, device: ComputeDevice) -> TrainConfig {
    config.threads = 1;
    config.sac_threads_alone = 0;
    config.device = device;
    config
}

/// Trains every member of `population` to its budget, recording this process in each member's
/// provenance first; `hook` (the crash-point tests') is called at every moment of every member,
/// one at a time, and `on_metrics` with each evaluation line a member writes (its error ends
/// the training).
pub fn train_population<P: Members>(
    population: &mut P,
    build: &Build,
    hook: Option<Hook>,
    mut on_metrics: impl FnMut(
        &Run<P::Learner>,
        &<P::Learner as Learner>::Metrics,
    ) -> Result<(), BoxError>,
) -> Result<(), RlError>
where
    P::Learner: InWords,
{
    if let Some(hook) = hook {
        let shared = Arc::new(Mutex::new(hook));
        for member in population.members_mut() {
            let shared = Arc::clone(&shared);
            member.set_hook(Box::new(move |moment| {
                if let Ok(mut hook) = shared.lock() {
                    hook(moment);
                }
            }));
        }
    }
    for member in population.members() {
        crate::train::record_provenance(member, build)?;
    }
    while !population.finished() {
        let events = population.step()?;
        for (member, event) in population.members().iter().zip(events) {
            if let Some(metrics) = event.as_ref().and_then(|e| e.metrics.as_ref()) {
                on_metrics(member, metrics).map_err(|source| {
                    RlError::from(seads_run::RunError::Io {
                        path: member.dir().display().to_string(),
                        source,
                    })
                })?;
            }
        }
    }
    Ok(())
}
