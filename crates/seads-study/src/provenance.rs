//! Which code on which machine trained which part of a run: each training process (a new run or a
//! resume, from `seads train`, `seads sweep task`, the demo or the robot) appends one line to the
//! run's `provenance.jsonl` before its first epoch.
//!
//! Runs with `portable_numerics = false` (the presets) repeat exactly only on the same kind of
//! processor, and portable runs differed between an AMD EPYC and an Intel Xeon until Adam took
//! its square root correctly rounded (docs/RESULTS.md, "Determinism across processors"), so a
//! committed result names its processor and commit here.

use std::path::Path;

use seads_planner::Evaluator;
use seads_run::ComputeDevice;
use serde::{Deserialize, Serialize};

/// The file in a run directory.
pub const PROVENANCE: &str = "provenance.jsonl";

/// The binary that trains: its version and the commit it was built from (the `seads` binary
/// stamps them at build time).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Build<'a> {
    /// The seads version.
    pub version: &'a str,
    /// The git commit.
    pub commit: &'a str,
    /// Whether tracked files differed from that commit.
    pub dirty: bool,
}

impl Build<'_> {
    /// Whether a study may train with this binary: one built from a working tree with uncommitted
    /// changes is refused ([`crate::StudyError::Invalid`], one line) unless `allow_dirty`, so that a
    /// study's runs come from code that is committed. A run it trains anyway says `dirty: true`
    /// in its provenance.
    pub fn allows_study(&self, allow_dirty: bool) -> crate::Result<()> {
        if self.dirty && !allow_dirty {
            return Err(crate::StudyError::invalid(format!(
                "this seads binary was built from a working tree with uncommitted changes (on {}), \
                 so a study's runs could not be traced to committed code: commit and rebuild, or \
                 pass --allow-dirty",
                self.commit
            )));
        }
        Ok(())
    }

    /// The binary as an evaluation file records it.
    pub fn evaluator(&self) -> Evaluator {
        Evaluator {
            seads: self.version.to_owned(),
            commit: self.commit.to_owned(),
            dirty: self.dirty,
        }
    }

    /// Declares this process's binary, once, before it evaluates: every evaluation file it
    /// writes names it (`evaluated_by`), and a stopped evaluation's journal names it beside each
    /// task it finished. A later declaration is ignored. The binary knows its own commit (it is
    /// stamped at build time); a library cannot, so a process that declares none writes
    /// evaluations that name no binary.
    pub fn declare(&self) {
        let _ = THIS_BINARY.set(self.evaluator());
    }
}

/// The binary this process declared ([`Build::declare`]).
static THIS_BINARY: std::sync::OnceLock<Evaluator> = std::sync::OnceLock::new();

/// The binary this process declared, if it did.
pub fn this_binary() -> Option<&'static Evaluator> {
    THIS_BINARY.get()
}

/// One training process of a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// The epoch this process trained first (0 for a new run; the checkpoint's for a resume).
    pub epoch: u64,
    /// Environment steps of the run when this process started.
    pub env_steps: u64,
    /// The seads version (Cargo.toml).
    pub seads: String,
    /// The git commit the binary was built from ("VERGEN_IDEMPOTENT_OUTPUT" outside a checkout).
    pub commit: String,
    /// Whether tracked files differed from that commit when the binary was built.
    pub dirty: bool,
    /// The processor's vendor (`GenuineIntel`, `AuthenticAMD`), if it tells.
    pub cpu_vendor: Option<String>,
    /// The processor's brand string, if it tells.
    pub cpu_model: Option<String>,
    /// Whether the processor has AVX-512 (MKL's fast kernels differ with it).
    pub avx512: bool,
    /// Logical processors this process could use.
    pub logical_cpus: usize,
    /// The run's `portable_numerics` (MKL's `COMPATIBLE` branch when true).
    pub portable_numerics: bool,
    /// Where the networks ran (`cpu`, `cuda:N`); lines from before devices say nothing: `cpu`.
    #[serde(default)]
    pub device: ComputeDevice,
    /// The GPU's name as its driver reports it, for a CUDA device.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gpu: Option<String>,
    /// When this process started, in seconds since the Unix epoch.
    pub started_unix_s: u64,
}

impl Provenance {
    /// This process of the binary `build`, about to train from `epoch` and `env_steps` on
    /// `device`.
    pub fn here(
        epoch: u64,
        env_steps: u64,
        portable_numerics: bool,
        device: ComputeDevice,
        build: &Build,
    ) -> Self {
        let (cpu_vendor, cpu_model, avx512) = cpu();
        Self {
            epoch,
            env_steps,
            seads: build.version.to_owned(),
            commit: build.commit.to_owned(),
            dirty: build.dirty,
            cpu_vendor,
            cpu_model,
            avx512,
            logical_cpus: std::thread::available_parallelism().map_or(1, |n| n.get()),
            portable_numerics,
            device,
            gpu: device.gpu_name(),
            started_unix_s: std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_secs()),
        }
    }

    /// The processors that trained the run in `run_dir`, distinct, in the order they first
    /// trained it ("unknown" for one that did not tell); empty for a run without the file
    /// (trained before 2026-11-25's provenance, or never trained).
    pub fn processors(run_dir: &Path) -> Result<Vec<String>, seads_run::RunError> {
        let path = run_dir.join(PROVENANCE);
        if !path.is_file() {
            return Ok(Vec::new());
        }
        let (lines, _) = seads_run::store::read_json_lines::<Provenance>(&path)?;
        let mut seen: Vec<String> = Vec::new();
        for line in lines {
            let cpu = line.cpu_model.unwrap_or_else(|| "unknown".to_owned());
            if !seen.contains(&cpu) {
                seen.push(cpu);
            }
        }
        Ok(seen)
    }

    /// Appends this process of `build` to the provenance of the run in `run_dir` with `config`,
    /// about to train it on from `epoch` and `env_steps` (the caller skips a finished run).
    pub fn record(
        run_dir: &Path,
        config: &seads_run::TrainConfig,
        (epoch, env_steps): (u64, u64),
        build: &Build,
    ) -> Result<(), seads_run::RunError> {
        let here = Self::here(
            epoch,
            env_steps,
            config.portable_numerics,
            config.device,
            build,
        );
        here.append(run_dir)
    }

    /// Appends this line to `run_dir`'s provenance file (a torn last line is repaired first).
    pub fn append(&self, run_dir: &Path) -> Result<(), seads_run::RunError> {
        seads_run::store::append_json_line(&run_dir.join(PROVENANCE), self)
    }
}

/// Vendor, brand string and AVX-512 of this processor.
#[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
fn cpu() -> (Option<String>, Option<String>, bool) {
    let id = raw_cpuid::CpuId::new();
    let vendor = id.get_vendor_info().map(|v| v.as_str().to_string());
    let model = id
        .get_processor_brand_string()
        .map(|b| b.as_str().trim().to_string());
    let avx512 = id
        .get_extended_feature_info()
        .is_some_and(|f| f.has_avx512f());
    (vendor, model, avx512)
}

/// Vendor, brand string and AVX-512 of this processor (not x86: unknown).
#[cfg(not(any(target_arch = "x86", target_arch = "x86_64")))]
fn cpu() -> (Option<String>, Option<String>, bool) {
    (None, None, false)
}

#[cfg(test)]
mod tests {
    use super::Build;

    #[test]
    fn a_study_refuses_a_dirty_binary_unless_allowed() {
        let build = |dirty| Build {
            version: "0.1.0",
            commit: "abc123",
            dirty,
        };
        let refused = build(true).allows_study(false).unwrap_err();
        assert!(refused.is_invalid());
        let message = refused.to_string();
        assert!(message.contains("uncommitted changes") && message.contains("--allow-dirty"));
        assert!(!message.contains('\n'), "one line: {message}");
        assert!(build(true).allows_study(true).is_ok());
        assert!(build(false).allows_study(false).is_ok());
    }
}
