//! Why the GPU backend cannot render.

use thiserror::Error;

/// Why the GPU backend cannot render.
#[derive(Debug, Error)]
pub enum GpuError {
    /// No adapter could be opened.
    #[error(
        "no GPU adapter found ({0}). For software rendering install Vulkan's CPU driver \
         (Debian/Ubuntu: apt-get install mesa-vulkan-drivers libvulkan1, which provide \
         lavapipe); if WGPU_BACKEND is set, it must name a backend this machine has; \
         or render with --backend cpu"
    )]
    NoAdapter(String),
    /// The scene holds something the GPU backend does not do yet.
    #[error("the GPU backend does not render {table} yet ({why}); use --backend cpu")]
    Unsupported {
        /// The config table or key.
        table: String,
        /// What is missing.
        why: String,
    },
    /// A buffer would exceed the adapter's limits.
    #[error(
        "{what} needs {need_mib:.1} MiB in one GPU buffer; the adapter allows {limit_mib:.1} MiB"
    )]
    TooLarge {
        /// Which data.
        what: String,
        /// Needed (MiB).
        need_mib: f64,
        /// Allowed (MiB).
        limit_mib: f64,
    },
    /// The shader did not compile or validate.
    #[error("GPU shader: {0}")]
    Shader(String),
    /// The device was lost (driver reset, out of memory...).
    #[error("the GPU device was lost: {0}")]
    DeviceLost(String),
    /// Any other error reported by the device.
    #[error("GPU: {0}")]
    Device(String),
    /// The render was stopped from outside
    /// ([`Prepared::stop_on`](super::Prepared::stop_on)).
    #[error("the render was stopped")]
    Stopped,
}
