//! Reading results back to the host: waiting for a mapping natively, a
//! callback in the browser.

use super::{Gpu, GpuError};
use std::sync::{Arc, Mutex};

impl Gpu {
    /// A buffer of `size` bytes to copy results into and read back.
    pub(super) fn readback(&self, label: &str, size: u64) -> wgpu::Buffer {
        self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: size.max(4),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    }

    /// Maps `buf`, copies out its first `size` bytes as `T`s, unmaps.
    pub(super) fn read<T: bytemuck::Pod>(
        &self,
        buf: &wgpu::Buffer,
        size: u64,
    ) -> Result<Vec<T>, GpuError> {
        self.read_with(buf, size, |v: &[T]| v.to_vec())
    }

    /// [`Gpu::read`] handing the mapped words to `f` instead of copying
    /// them out (a 1080p film is 33 MB a frame).
    pub(super) fn read_with<T: bytemuck::Pod, R>(
        &self,
        buf: &wgpu::Buffer,
        size: u64,
        f: impl FnOnce(&[T]) -> R,
    ) -> Result<R, GpuError> {
        if cfg!(target_arch = "wasm32") {
            return Err(GpuError::Device(
                "the browser cannot wait for the GPU's results: read them back with a callback"
                    .into(),
            ));
        }
        let slice = buf.slice(..size);
        let done = Arc::new(Mutex::new(None));
        let flag = done.clone();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            *flag.lock().expect("map flag") = Some(r);
        });
        // Another thread's poll may run this mapping's callback just after
        // ours returns: wait for the callback itself.
        let mut tries = 0u32;
        let result = loop {
            self.device
                .poll(wgpu::PollType::wait_indefinitely())
                .map_err(|e| GpuError::Device(format!("waiting for the GPU: {e}")))?;
            self.check()?;
            if let Some(r) = done.lock().expect("map flag").take() {
                break r;
            }
            tries += 1;
            if tries > 10_000 {
                return Err(GpuError::Device("the GPU did not finish".into()));
            }
            std::thread::sleep(std::time::Duration::from_millis(1));
        };
        result.map_err(|e| GpuError::Device(format!("reading results back: {e}")))?;
        let out = {
            let view = slice
                .get_mapped_range()
                .map_err(|e| GpuError::Device(format!("reading results back: {e}")))?;
            f(bytemuck::cast_slice::<u8, T>(&view))
        };
        buf.unmap();
        Ok(out)
    }
}

/// Maps the read-back buffer `buf` and hands its bytes to `f` when the GPU
/// has them, without waiting (the browser's read-back; natively `f` runs
/// on a later poll); unmapped after.
pub(super) fn read_later(
    buf: wgpu::Buffer,
    f: impl FnOnce(Result<&[u8], GpuError>) + Send + 'static,
) {
    let mapped = buf.clone();
    buf.slice(..).map_async(wgpu::MapMode::Read, move |r| {
        let failed = |e: &dyn std::fmt::Display| GpuError::Device(format!("reading back: {e}"));
        match r
            .map_err(|e| failed(&e))
            .and_then(|()| mapped.slice(..).get_mapped_range().map_err(|e| failed(&e)))
        {
            Ok(view) => {
                f(Ok(&view));
                drop(view);
                mapped.unmap();
            }
            Err(e) => f(Err(e)),
        }
    });
}
