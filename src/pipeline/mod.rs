//! One frame pipeline for every command.
//!
//! A [`Backend`] is opened once (the CPU, or a GPU device); a scene is
//! [prepared](Backend::prepare) on it once (on the GPU: uploaded and its
//! shader compiled) and then moved (another instant, a stereo eye, other
//! rows) for each film it renders; the films go through the same post
//! (bloom, stereo composites) and one output plan ([`Outputs`], with the
//! checks of [`crate::files::Plan`] and the all-or-nothing writes of
//! [`crate::files::Batch`]). `render`, its tiles and `merge`, `compare`,
//! `animate` and the viewer's screenshots all go this way.

mod backend;
#[cfg(not(target_arch = "wasm32"))]
mod estimate;
mod frames;
mod outputs;
mod report;

pub use backend::{Backend, BackendKind, Prepared};
#[cfg(not(target_arch = "wasm32"))]
pub use estimate::{Estimate, duration_text, estimate};
pub use frames::{FRAME_NUMBER, FRAME_SCENE, frame_file, frame_is_complete};
pub use outputs::{Outputs, check_memory, guard_outputs, plan_of};
pub use report::{percent, summary_line, warn_lost};
