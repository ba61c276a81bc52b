//! The viewer's own events, apart from the window's input: the one type
//! that the viewer (`app.rs`) and the page's glue (`web.rs`) share, so that
//! the glue depends on it and not on the viewer.

use super::Session;
use crate::gpu::{Gpu, GpuError};

/// What reaches the viewer through its event loop besides the window's
/// input: in the browser, the GPU (whose adapter and device are promises),
/// the page's buttons and the GPU's "frame done".
pub enum Event {
    /// The GPU opened for the window's surface.
    Gpu(Box<Result<(Gpu, wgpu::Surface<'static>), GpuError>>),
    /// Another scene to view (its files fetched).
    Open(Box<Session>),
    /// Save the view as a scene file.
    Save,
    /// Keep the image shown as a PNG.
    Screenshot,
    /// A control's key pressed through the page's buttons (for screens
    /// without a keyboard): a character, or " " for space.
    Key(String),
    /// The GPU finished a frame's work.
    Done,
}
