//! Where the networks run: a [`ComputeDevice`] as a run's configuration names it (`seads-run`),
//! resolved to libtorch's device once it is known to exist.

use tch::Device;

pub use seads_run::{ComputeDevice, DeviceError};

/// libtorch's device for a [`ComputeDevice`].
pub trait Resolve {
    /// The tch device, once it is known to exist: CUDA must be built in and the GPU visible.
    fn resolve(self) -> Result<Device, DeviceError>;
}

impl Resolve for ComputeDevice {
    fn resolve(self) -> Result<Device, DeviceError> {
        match self {
            ComputeDevice::Cpu => Ok(Device::Cpu),
            ComputeDevice::Cuda(index) => {
                if !tch::utils::has_cuda() {
                    return Err(DeviceError::NoCudaBuild(self));
                }
                let count = usize::try_from(tch::Cuda::device_count()).unwrap_or(0);
                if count == 0 || !tch::Cuda::is_available() {
                    return Err(DeviceError::NoGpu(self));
                }
                if index >= count {
                    return Err(DeviceError::NoSuchGpu {
                        device: self,
                        count,
                    });
                }
                Ok(Device::Cuda(index))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cpu_resolves_and_a_missing_gpu_is_an_error_that_says_why() {
        assert_eq!(ComputeDevice::Cpu.resolve(), Ok(Device::Cpu));
        // This test binary does not link libtorch_cuda (the `cuda` feature is the binary's), so
        // CUDA is never registered here, GPU or not.
        let err = ComputeDevice::Cuda(0).resolve().unwrap_err();
        assert_eq!(err, DeviceError::NoCudaBuild(ComputeDevice::Cuda(0)));
        let line = err.to_string();
        assert!(
            line.contains("cuda:0") && line.contains("--features cuda"),
            "{line}"
        );
    }
}
