//! A run directory's checkpoints: which one, and the tensors in its safetensors files.

use std::path::{Path, PathBuf};

use ndarray::{Array1, Array2};
use seads_weights::Weights;

use crate::InferError;
use crate::mlp::{Dense, Mlp};

/// The directory of the checkpoint of `epoch` in the run `run`, or of the latest one (the one
/// `checkpoints/latest` names, else the highest epoch).
pub fn checkpoint_dir(run: &Path, epoch: Option<u64>) -> Result<PathBuf, InferError> {
    let dir = run.join("checkpoints");
    if let Some(epoch) = epoch {
        let path = dir.join(format!("epoch-{epoch:06}"));
        return if path.is_dir() {
            Ok(path)
        } else {
            Err(InferError::Missing(format!(
                "{}: no checkpoint of epoch {epoch}",
                run.display()
            )))
        };
    }
    if let Ok(name) = std::fs::read_to_string(dir.join("latest")) {
        let name = name.trim();
        if name.starts_with("epoch-") && !name.contains(['/', '\\']) && dir.join(name).is_dir() {
            return Ok(dir.join(name));
        }
    }
    let entries = std::fs::read_dir(&dir).map_err(|e| InferError::Io {
        what: format!("reading {}", dir.display()),
        source: e,
    })?;
    entries
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            let name = e.file_name().into_string().ok()?;
            let epoch: u64 = name.strip_prefix("epoch-")?.parse().ok()?;
            e.path().is_dir().then_some((epoch, e.path()))
        })
        .max_by_key(|(epoch, _)| *epoch)
        .map(|(_, path)| path)
        .ok_or_else(|| InferError::Missing(format!("{}: no checkpoint", run.display())))
}

/// The float32 tensors of one safetensors file, by name, read and checked by
/// [`seads_weights::Weights`], the reader the binary loads its networks through too.
pub struct Tensors {
    weights: Weights,
}

impl Tensors {
    /// Reads `path`.
    pub fn read(path: &Path) -> Result<Self, InferError> {
        Ok(Self {
            weights: Weights::read(path)?,
        })
    }

    fn damaged(&self, reason: String) -> InferError {
        InferError::Damaged {
            path: self.weights.path().display().to_string(),
            reason,
        }
    }

    /// Whether a tensor called `name` is there.
    pub fn has(&self, name: &str) -> bool {
        self.weights.has(name)
    }

    /// The float32 tensor `name` as a flat vector and its shape (finite values only).
    pub fn get(&self, name: &str) -> Result<(Vec<f32>, Vec<usize>), InferError> {
        Ok(self.weights.get(name)?)
    }

    /// The linear layer `{prefix}.weight`, `{prefix}.bias`.
    pub fn dense(&self, prefix: &str) -> Result<Dense, InferError> {
        let (w, wshape) = self.get(&format!("{prefix}.weight"))?;
        let (b, bshape) = self.get(&format!("{prefix}.bias"))?;
        let [rows, cols] = wshape[..] else {
            return Err(self.damaged(format!("{prefix}.weight has shape {wshape:?}")));
        };
        if bshape.len() != 1 {
            return Err(self.damaged(format!("{prefix}.bias has shape {bshape:?}")));
        }
        let weight = Array2::from_shape_vec((rows, cols), w)
            .map_err(|e| self.damaged(format!("{prefix}.weight: {e}")))?;
        Dense::new(weight, Array1::from_vec(b), prefix)
    }

    /// The perceptron of layers `{prefix}.layer0`, `{prefix}.layer1`, … as many as there are.
    pub fn mlp(&self, prefix: &str) -> Result<Mlp, InferError> {
        let mut layers = Vec::new();
        while self.has(&format!("{prefix}.layer{}.weight", layers.len())) {
            layers.push(self.dense(&format!("{prefix}.layer{}", layers.len()))?);
        }
        Mlp::new(layers, prefix)
    }
}
