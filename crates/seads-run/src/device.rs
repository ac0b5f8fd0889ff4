//! Where the networks run: the CPU (the default, bit-exact across runs) or a CUDA GPU.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// A device as users name it: `cpu`, `cuda` (the first GPU) or `cuda:N`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum ComputeDevice {
    /// The CPU (the default).
    #[default]
    Cpu,
    /// The CUDA GPU of this index (`cuda` is `cuda:0`).
    Cuda(usize),
}

/// Why a device cannot be used.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DeviceError {
    /// The name is none of `cpu`, `cuda`, `cuda:N`.
    #[error("device {0:?} is not one of cpu, cuda, cuda:N")]
    Parse(String),
    /// The binary's libtorch has no CUDA support registered.
    #[error(
        "device {0} needs a CUDA build of seads (cargo build --release -p seads-cli --features \
         cuda after scripts/setup.sh --cuda; README, \"On a GPU\")"
    )]
    NoCudaBuild(ComputeDevice),
    /// CUDA is built in, but this machine shows no GPU.
    #[error("device {0}: CUDA is built in, but no GPU is visible (driver, CUDA_VISIBLE_DEVICES)")]
    NoGpu(ComputeDevice),
    /// The index is past the GPUs present.
    #[error("device {device} does not exist: this machine has {count} GPU(s), cuda:0 to cuda:{last}", last = count - 1)]
    NoSuchGpu {
        /// The device asked for.
        device: ComputeDevice,
        /// GPUs visible.
        count: usize,
    },
}

impl ComputeDevice {
    /// Whether this is the processor.
    pub fn is_cpu(&self) -> bool {
        *self == Self::Cpu
    }

    /// Whether this is a GPU.
    pub fn is_cuda(self) -> bool {
        matches!(self, Self::Cuda(_))
    }

    /// The GPU's product name (e.g. "NVIDIA H100 80GB HBM3") as the NVIDIA driver reports it,
    /// `None` for the CPU or where the driver does not say. CUDA numbers GPUs fastest first
    /// unless `CUDA_DEVICE_ORDER=PCI_BUS_ID`; the name is the driver's for that index.
    pub fn gpu_name(self) -> Option<String> {
        let Self::Cuda(index) = self else {
            return None;
        };
        let output = std::process::Command::new("nvidia-smi")
            .args([
                "--query-gpu=name",
                "--format=csv,noheader",
                &format!("--id={index}"),
            ])
            .output()
            .ok()?;
        let name = String::from_utf8_lossy(&output.stdout).trim().to_string();
        (output.status.success() && !name.is_empty()).then_some(name)
    }
}

impl fmt::Display for ComputeDevice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Cpu => f.write_str("cpu"),
            Self::Cuda(index) => write!(f, "cuda:{index}"),
        }
    }
}

impl FromStr for ComputeDevice {
    type Err = DeviceError;

    fn from_str(s: &str) -> Result<Self, DeviceError> {
        let bad = || DeviceError::Parse(s.to_string());
        match s.trim().to_ascii_lowercase().as_str() {
            "cpu" => Ok(Self::Cpu),
            "cuda" => Ok(Self::Cuda(0)),
            other => {
                let index = other.strip_prefix("cuda:").ok_or_else(bad)?;
                // Digits only: "+1", " 1" and "1_000" are not indices.
                if index.is_empty() || !index.bytes().all(|b| b.is_ascii_digit()) {
                    return Err(bad());
                }
                index.parse().map(Self::Cuda).map_err(|_| bad())
            }
        }
    }
}

impl Serialize for ComputeDevice {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for ComputeDevice {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let s = String::deserialize(deserializer)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn names_parse_as_documented() {
        assert_eq!("cpu".parse(), Ok(ComputeDevice::Cpu));
        assert_eq!("CPU".parse(), Ok(ComputeDevice::Cpu));
        assert_eq!("cuda".parse(), Ok(ComputeDevice::Cuda(0)));
        assert_eq!("cuda:0".parse(), Ok(ComputeDevice::Cuda(0)));
        assert_eq!("cuda:3".parse(), Ok(ComputeDevice::Cuda(3)));
        for bad in [
            "", "cuda:", "cuda:-1", "cuda:+1", "cuda:1.5", "cuda:x", "tpu", "cuda:1:2", "mps",
            "cuda: 1", "gpu",
        ] {
            assert_eq!(
                bad.parse::<ComputeDevice>(),
                Err(DeviceError::Parse(bad.to_string())),
                "{bad:?}"
            );
        }
        let huge = format!("cuda:{}0", usize::MAX);
        assert!(huge.parse::<ComputeDevice>().is_err());
    }

    #[test]
    fn a_missing_gpu_says_how_many_there_are() {
        assert_eq!(ComputeDevice::Cpu.gpu_name(), None);
        let none = DeviceError::NoSuchGpu {
            device: ComputeDevice::Cuda(4),
            count: 2,
        };
        assert_eq!(
            none.to_string(),
            "device cuda:4 does not exist: this machine has 2 GPU(s), cuda:0 to cuda:1"
        );
    }

    #[test]
    fn toml_holds_the_name() {
        #[derive(Serialize, Deserialize, PartialEq, Debug)]
        struct C {
            device: ComputeDevice,
        }
        let c: C = toml::from_str("device = \"cuda:1\"").unwrap();
        assert_eq!(c.device, ComputeDevice::Cuda(1));
        assert_eq!(toml::to_string(&c).unwrap().trim(), "device = \"cuda:1\"");
        let e = toml::from_str::<C>("device = \"gpu:1\"").unwrap_err();
        assert!(
            e.to_string().contains("not one of cpu, cuda, cuda:N"),
            "{e}"
        );
    }

    proptest! {
        #[test]
        fn display_and_parse_round_trip(index in 0usize..1_000_000, cuda in any::<bool>()) {
            let device = if cuda { ComputeDevice::Cuda(index) } else { ComputeDevice::Cpu };
            prop_assert_eq!(device.to_string().parse::<ComputeDevice>(), Ok(device));
        }

        #[test]
        fn no_string_panics(s in "\\PC{0,12}") {
            let _ = s.parse::<ComputeDevice>();
        }
    }
}
