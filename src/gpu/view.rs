//! The viewer's frames: passes added up into the display's image on the
//! GPU, bloomed and encoded into an 8-bit texture that a window draws, and
//! that image read back when asked.

use super::readback::read_later;
use super::traced::{Show, Want};
use super::{GpuError, Prepared, display};
use crate::film::Stats;
use glam::Vec3;

/// A frame of the viewer ([`Prepared::view_pass`]): its image is on the
/// GPU ([`Prepared::view_texture`]).
#[derive(Clone, Copy, Debug)]
pub struct ViewFrame {
    /// The image's size (smaller than the scene's for a preview).
    pub width: u32,
    pub height: u32,
    /// The pass's counts.
    pub stats: Stats,
}

impl Prepared<'_> {
    /// The viewer's frame: samples `first..first + count` of every pixel,
    /// on an image `scale` times smaller each way (a preview) or whole,
    /// added to the view's image on the GPU (`restart`: the image starts
    /// again with them), bloomed and encoded into the 8-bit texture of
    /// [`Prepared::view_texture`]; only the counts are read back.
    pub fn view_pass(
        &self,
        first: u32,
        count: u32,
        scale: u32,
        restart: bool,
    ) -> Result<ViewFrame, GpuError> {
        let want = Want {
            film: false,
            bands: false,
            show: Some(Show {
                restart,
                encode: true,
                read_bloomed: false,
            }),
        };
        let t = self.scaled_pass(first, count, scale, &|_| {}, want)?;
        Ok(ViewFrame {
            width: t.width,
            height: t.height,
            stats: t.stats,
        })
    }

    /// The viewer's 8-bit sRGB texture (RGBA, the scene's size; a
    /// preview fills its top-left corner), for drawing.
    pub fn view_texture(&self) -> Result<wgpu::TextureView, GpuError> {
        self.with_display(|d| Ok(d.view().clone()))
    }

    /// The viewer's image as the window shows it: 8-bit sRGB RGB bytes of
    /// its top-left `width` x `height` (the last [`ViewFrame`]'s size).
    pub fn read_view(&self, width: u32, height: u32) -> Result<Vec<u8>, GpuError> {
        let (row, copy) = view_copy(width, height);
        self.read_display(row as u64 * height as u64, copy, |bytes: &[u8]| {
            unpadded_rgb(bytes, row, width)
        })
    }

    /// [`Prepared::read_view`] for the browser, which cannot wait for the
    /// GPU: `done` gets the bytes when they come.
    pub fn read_view_later(
        &self,
        width: u32,
        height: u32,
        done: impl FnOnce(Result<Vec<u8>, GpuError>) + Send + 'static,
    ) -> Result<(), GpuError> {
        let (row, copy) = view_copy(width, height);
        let buf = self.copy_display(row as u64 * height as u64, copy)?;
        read_later(buf, move |bytes| {
            done(bytes.map(|b| unpadded_rgb(b, row, width)))
        });
        Ok(())
    }

    /// The viewer's image before bloom and tone mapping: the mean XYZ of
    /// its samples so far, `width` x `height` (the last [`ViewFrame`]'s).
    pub fn read_view_film(&self, width: u32, height: u32) -> Result<Vec<Vec3>, GpuError> {
        let size = 16 * width as u64 * height as u64;
        let copy = |enc: &mut wgpu::CommandEncoder, d: &display::Display, buf: &wgpu::Buffer| {
            enc.copy_buffer_to_buffer(d.acc(), 0, buf, 0, size)
        };
        self.read_display(size, copy, |w: &[f32]| {
            w.chunks_exact(4)
                .map(|c| Vec3::new(c[0], c[1], c[2]))
                .collect()
        })
    }

    /// `size` bytes of the display that `copy` copies into a read-back
    /// buffer, handed to `read` as `T`s.
    fn read_display<T: bytemuck::Pod, R>(
        &self,
        size: u64,
        copy: impl FnOnce(&mut wgpu::CommandEncoder, &display::Display, &wgpu::Buffer),
        read: impl FnOnce(&[T]) -> R,
    ) -> Result<R, GpuError> {
        let buf = self.copy_display(size, copy)?;
        self.gpu.read_with(&buf, size, read)
    }

    /// A read-back buffer of `size` bytes into which `copy` copies from the
    /// display (submitted, not waited for).
    fn copy_display(
        &self,
        size: u64,
        copy: impl FnOnce(&mut wgpu::CommandEncoder, &display::Display, &wgpu::Buffer),
    ) -> Result<wgpu::Buffer, GpuError> {
        let gpu = self.gpu;
        let buf = gpu.readback("the display, read back", size);
        self.with_display(|d| {
            let mut enc = gpu
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
            copy(&mut enc, d, &buf);
            gpu.queue.submit([enc.finish()]);
            Ok(())
        })?;
        Ok(buf)
    }

    /// Runs `f` on the display, made first if need be.
    pub(super) fn with_display<R>(
        &self,
        f: impl FnOnce(&mut display::Display) -> Result<R, GpuError>,
    ) -> Result<R, GpuError> {
        let mut slot = self.display.lock().expect("display");
        if slot.is_none() {
            *slot = Some(display::Display::new(
                self.gpu,
                self.gpu.display_pipelines()?,
                self.look.clone(),
                &self.film,
                &self.bands,
                self.width,
                self.height,
            )?);
        }
        f(slot.as_mut().expect("made"))
    }
}

/// The bytes per row of the viewer's `width`-wide texture read back, and
/// the copy of its top-left `width` x `height` into a read-back buffer.
fn view_copy(
    width: u32,
    height: u32,
) -> (
    u32,
    impl FnOnce(&mut wgpu::CommandEncoder, &display::Display, &wgpu::Buffer),
) {
    let row = (4 * width).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
        * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let copy = move |enc: &mut wgpu::CommandEncoder, d: &display::Display, buf: &wgpu::Buffer| {
        enc.copy_texture_to_buffer(
            d.texture().as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: buf,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: None,
                },
            },
            wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
        )
    };
    (row, copy)
}

/// RGB bytes of RGBA rows `row` bytes apart, `width` pixels each.
fn unpadded_rgb(bytes: &[u8], row: u32, width: u32) -> Vec<u8> {
    bytes
        .chunks_exact(row as usize)
        .flat_map(|r| {
            r[..4 * width as usize]
                .chunks_exact(4)
                .flat_map(|p| [p[0], p[1], p[2]])
        })
        .collect()
}
