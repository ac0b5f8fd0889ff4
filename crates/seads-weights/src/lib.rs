//! A checkpoint's network weights without libtorch: one safetensors file, read once and checked.
//!
//! Every network file of a checkpoint goes through [`Weights`], whoever reads it: the `seads`
//! binary before libtorch sees a value (`seads_nn::load_var_store`), and the Python package's
//! agent (`seads-infer`). So both refuse the same damaged files, each in one message that names
//! the file and what is wrong with it:
//! - anything but a regular file (a FIFO, `/dev/zero`), or one larger than [`MAX_FILE_BYTES`];
//! - a header or layout that is not safetensors';
//! - a tensor that is not float32, or holds NaN or an infinity;
//! - where the reader knows the network, a missing or extra tensor, or a shape that is not
//!   exactly the network's (a `[1, 32]` weight for `[32, 32]` would otherwise broadcast).
//!
//! The header is parsed once, so a file of many tensors reads in time linear in its size.
//!
//! ```
//! use seads_weights::{Weights, WeightsError};
//! # let dir = tempfile::tempdir()?;
//! # let path = dir.path().join("net.safetensors");
//! # let header = r#"{"layer0.weight":{"dtype":"F32","shape":[1,2],"data_offsets":[0,8]}}"#;
//! # let mut file = (header.len() as u64).to_le_bytes().to_vec();
//! # file.extend(header.as_bytes());
//! # file.extend([1.0f32, 2.0].iter().flat_map(|v| v.to_le_bytes()));
//! # std::fs::write(&path, file)?;
//! let weights = Weights::read(&path)?;
//! assert_eq!(weights.tensor("layer0.weight", &[1, 2])?, vec![1.0, 2.0]);
//! // A shape that merely broadcasts is not the network's.
//! let err = weights.tensor("layer0.weight", &[2, 2]).unwrap_err();
//! assert!(matches!(err, WeightsError::Damaged { .. }), "{err}");
//! assert!(weights.exactly(["layer0.weight", "layer0.bias"]).is_err());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::collections::BTreeMap;
use std::io::Read as _;
use std::path::{Path, PathBuf};

use safetensors::tensor::TensorInfo;
use safetensors::{Dtype, SafeTensors};

/// Why a file's weights cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum WeightsError {
    /// The file could not be read.
    #[error("reading {path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The file is not weights a network can take.
    #[error("{path}: {reason}")]
    Damaged {
        /// The file.
        path: String,
        /// What is wrong.
        reason: String,
    },
}

/// The largest weights file read: 4 GiB, far above any network of the paper (a few MB), so that
/// a file that is no checkpoint is refused before it fills the memory.
pub const MAX_FILE_BYTES: u64 = 1 << 32;

/// The tensors of one safetensors file, by name, with their layout parsed once.
#[derive(Debug)]
pub struct Weights {
    path: PathBuf,
    bytes: Vec<u8>,
    /// Where the data begin: after the 8-byte header length and the header.
    data_start: usize,
    tensors: BTreeMap<String, TensorInfo>,
}

impl Weights {
    /// Reads and parses `path`: a regular file of at most [`MAX_FILE_BYTES`] whose header and
    /// layout are safetensors'. The values are checked as they are asked for.
    pub fn read(path: &Path) -> Result<Self, WeightsError> {
        let io = |source| WeightsError::Io {
            path: path.display().to_string(),
            source,
        };
        let damaged = |reason: String| WeightsError::Damaged {
            path: path.display().to_string(),
            reason,
        };
        // Links are followed: what they point to must be a file (not /dev/zero, not a FIFO).
        let meta = std::fs::metadata(path).map_err(io)?;
        if !meta.is_file() {
            return Err(damaged("not a regular file".into()));
        }
        if meta.len() > MAX_FILE_BYTES {
            return Err(damaged(format!(
                "{} bytes, more than the {MAX_FILE_BYTES} a weights file may have",
                meta.len()
            )));
        }
        let mut bytes = Vec::with_capacity(meta.len() as usize);
        std::fs::File::open(path)
            .and_then(|f| f.take(MAX_FILE_BYTES + 1).read_to_end(&mut bytes))
            .map_err(io)?;
        if bytes.len() as u64 > MAX_FILE_BYTES {
            return Err(damaged("the file grew while it was read".into()));
        }
        let (header, metadata) =
            SafeTensors::read_metadata(&bytes).map_err(|e| damaged(format!("{e:?}")))?;
        let tensors = metadata
            .tensors()
            .into_iter()
            .map(|(name, info)| (name, info.clone()))
            .collect();
        Ok(Self {
            path: path.to_owned(),
            bytes,
            data_start: 8 + header,
            tensors,
        })
    }

    fn damaged(&self, reason: String) -> WeightsError {
        WeightsError::Damaged {
            path: self.path.display().to_string(),
            reason,
        }
    }

    /// The file read.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The names of the tensors, in order.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.tensors.keys().map(String::as_str)
    }

    /// Whether a tensor called `name` is there.
    pub fn has(&self, name: &str) -> bool {
        self.tensors.contains_key(name)
    }

    /// The float32 tensor `name` as a flat vector and its shape; an error if it is missing, of
    /// another type, or holds NaN or an infinity.
    pub fn get(&self, name: &str) -> Result<(Vec<f32>, Vec<usize>), WeightsError> {
        let info = self
            .tensors
            .get(name)
            .ok_or_else(|| self.damaged(format!("no tensor {name}")))?;
        if info.dtype != Dtype::F32 {
            return Err(self.damaged(format!("{name} is {:?}, not F32", info.dtype)));
        }
        // The layout was validated on reading: the offsets lie within the data, and each
        // tensor's bytes are exactly its elements'.
        let (start, end) = info.data_offsets;
        let data = &self.bytes[self.data_start + start..self.data_start + end];
        let values: Vec<f32> = data
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        if let Some(bad) = values.iter().find(|v| !v.is_finite()) {
            return Err(self.damaged(format!("{name} holds {bad}")));
        }
        Ok((values, info.shape.clone()))
    }

    /// The float32 tensor `name`, which must have exactly `shape`.
    pub fn tensor(&self, name: &str, shape: &[usize]) -> Result<Vec<f32>, WeightsError> {
        let (values, found) = self.get(name)?;
        if found != shape {
            return Err(self.damaged(format!(
                "{name} has shape {found:?}, the network's is {shape:?}"
            )));
        }
        Ok(values)
    }

    /// Checks that the file holds exactly the tensors `names`, no more and no fewer.
    pub fn exactly<'a>(
        &self,
        names: impl IntoIterator<Item = &'a str>,
    ) -> Result<(), WeightsError> {
        let expected: std::collections::BTreeSet<&str> = names.into_iter().collect();
        if let Some(missing) = expected.iter().find(|n| !self.has(n)) {
            return Err(self.damaged(format!("no tensor {missing}")));
        }
        if let Some(extra) = self.names().find(|n| !expected.contains(n)) {
            return Err(self.damaged(format!("tensor {extra} is not one of the network's")));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A safetensors file of `tensors` (name, dtype name, shape, raw bytes), written by hand
    /// after the format's specification: the header's length as a little-endian u64, the JSON
    /// header, the data.
    fn file(tensors: &[(&str, &str, &[usize], Vec<u8>)]) -> Vec<u8> {
        let mut header = serde_json::Map::new();
        let mut data: Vec<u8> = Vec::new();
        for (name, dtype, shape, bytes) in tensors {
            header.insert(
                (*name).to_owned(),
                serde_json::json!({
                    "dtype": dtype,
                    "shape": shape,
                    "data_offsets": [data.len(), data.len() + bytes.len()],
                }),
            );
            data.extend(bytes);
        }
        let text = serde_json::to_vec(&header).unwrap();
        let mut out = (text.len() as u64).to_le_bytes().to_vec();
        out.extend(text);
        out.extend(data);
        out
    }

    fn f32s(values: &[f32]) -> Vec<u8> {
        values.iter().flat_map(|v| v.to_le_bytes()).collect()
    }

    fn written(bytes: &[u8]) -> (tempfile::TempDir, PathBuf) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("w.safetensors");
        std::fs::write(&path, bytes).unwrap();
        (dir, path)
    }

    fn reason(e: WeightsError) -> String {
        match e {
            WeightsError::Damaged { reason, .. } => reason,
            other => panic!("not damage: {other}"),
        }
    }

    #[test]
    fn values_and_shapes_read_back_exactly() {
        let (_dir, path) = written(&file(&[
            ("b", "F32", &[2], f32s(&[0.5, -1.0])),
            ("a", "F32", &[2, 1], f32s(&[3.0, 4.0])),
        ]));
        let w = Weights::read(&path).unwrap();
        assert_eq!(w.names().collect::<Vec<_>>(), ["a", "b"]);
        assert_eq!(w.get("a").unwrap(), (vec![3.0, 4.0], vec![2, 1]));
        assert_eq!(w.tensor("b", &[2]).unwrap(), vec![0.5, -1.0]);
        w.exactly(["b", "a"]).unwrap();
    }

    /// Each damage the fifth reliability probe (issue 82) made to one tensor is refused, with
    /// why.
    #[test]
    fn damaged_tensors_are_refused_with_why() {
        // (name, dtype, shape, bytes, the network's shape, why it is refused)
        type Case = (
            &'static str,
            &'static str,
            &'static [usize],
            Vec<u8>,
            &'static [usize],
            &'static str,
        );
        let cases: [Case; 7] = [
            (
                "w",
                "F32",
                &[1, 2],
                f32s(&[1.0, 2.0]),
                &[2, 2],
                "has shape [1, 2]",
            ),
            ("w", "F32", &[], f32s(&[1.0]), &[2], "has shape []"),
            ("w", "F32", &[2], f32s(&[1.0, f32::NAN]), &[2], "holds NaN"),
            (
                "w",
                "F32",
                &[2],
                f32s(&[f32::INFINITY, 1.0]),
                &[2],
                "holds inf",
            ),
            ("w", "F16", &[2], vec![0; 4], &[2], "is F16, not F32"),
            ("w", "F64", &[2], vec![0; 16], &[2], "is F64, not F32"),
            ("w", "I64", &[2], vec![0; 16], &[2], "is I64, not F32"),
        ];
        for (name, dtype, shape, bytes, expected, why) in cases {
            let (_dir, path) = written(&file(&[(name, dtype, shape, bytes)]));
            let w = Weights::read(&path).unwrap();
            let e = reason(w.tensor("w", expected).unwrap_err());
            assert!(e.contains(why), "{dtype} {shape:?}: {e}");
        }
        let (_dir, path) = written(&file(&[("w", "F32", &[1], f32s(&[1.0]))]));
        let w = Weights::read(&path).unwrap();
        assert!(reason(w.exactly(["w", "v"]).unwrap_err()).contains("no tensor v"));
        assert!(reason(w.exactly([]).unwrap_err()).contains("tensor w is not one"));
        assert!(reason(w.get("v").unwrap_err()).contains("no tensor v"));
    }

    #[test]
    fn files_that_are_no_weights_are_refused_before_they_are_read_whole() {
        let dir = tempfile::tempdir().unwrap();
        // Not a regular file: a directory, and /dev/zero through a link, which would be read
        // until memory runs out.
        assert!(reason(Weights::read(dir.path()).unwrap_err()).contains("not a regular file"));
        let zero = dir.path().join("zero.safetensors");
        std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
        assert!(reason(Weights::read(&zero).unwrap_err()).contains("not a regular file"));
        assert!(matches!(
            Weights::read(&dir.path().join("missing")),
            Err(WeightsError::Io { .. })
        ));
        // Layouts that are not safetensors': too short, a header past the end, data of the
        // wrong length.
        let good = file(&[("w", "F32", &[2], f32s(&[1.0, 2.0]))]);
        for bad in [
            &good[..4],
            &good[..good.len() - 1],
            b"\xff\xff\xff\xff\0\0\0\0{}",
        ] {
            let (_dir, path) = written(bad);
            assert!(matches!(
                Weights::read(&path),
                Err(WeightsError::Damaged { .. })
            ));
        }
    }

    proptest::proptest! {
        /// Whatever the bytes, reading them and asking for any tensor ends in a value or an
        /// error, never a panic.
        #[test]
        fn any_bytes_are_read_without_a_panic(
            bytes in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..256),
            header in proptest::option::of("[ -~]{0,80}"),
        ) {
            let bytes = match header {
                Some(text) => {
                    let mut out = (text.len() as u64).to_le_bytes().to_vec();
                    out.extend(text.as_bytes());
                    out.extend(&bytes);
                    out
                }
                None => bytes,
            };
            let (_dir, path) = written(&bytes);
            if let Ok(w) = Weights::read(&path) {
                let names: Vec<String> = w.names().map(str::to_owned).collect();
                for name in &names {
                    let _ = w.get(name);
                    let _ = w.tensor(name, &[1]);
                }
            }
        }
    }
}
