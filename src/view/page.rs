//! What the web viewer's page shows and offers, for the viewer and for
//! the page's own calls (web.rs): the state of the image as attributes of
//! `<body>` (for people and for tests), errors, the canvas, the saved view
//! and the screenshot as downloads.

use super::Session;
use super::event::Event;
use super::state::ViewState;
use crate::gpu::{Prepared, ViewFrame};
use anyhow::{Result, anyhow};
use std::cell::RefCell;
use wasm_bindgen::JsCast;
use wasm_bindgen::prelude::*;
use winit::event_loop::EventLoopProxy;

thread_local! {
    /// Frames drawn and frames whose GPU work is done, as the page shows
    /// them (`data-painted`, `data-done`: tests wait for them to move on).
    static COUNTS: std::cell::Cell<(u64, u64)> = const { std::cell::Cell::new((0, 0)) };
    /// An error is the page's state (until the next scene opens).
    static FAILED: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    /// The viewer's message as last shown: said once when it changes, so
    /// that a message from before ("saved ...") never covers a later error
    /// or loading line.
    static SHOWN: RefCell<String> = const { RefCell::new(String::new()) };
}

fn document() -> Result<web_sys::Document> {
    web_sys::window()
        .and_then(|w| w.document())
        .ok_or_else(|| anyhow!("no document"))
}

pub(super) fn js(e: JsValue) -> anyhow::Error {
    anyhow!(
        "{}",
        e.as_string()
            .or_else(|| js_sys::JSON::stringify(&e).ok().and_then(|s| s.as_string()))
            .unwrap_or_else(|| "a browser error".into())
    )
}

/// Sets `data-<key>` of `<body>` (the page's state, which tests wait on).
fn mark(key: &str, value: &str) {
    if let Some(body) = document().ok().and_then(|d| d.body()) {
        let _ = body.set_attribute(&format!("data-{key}"), value);
    }
}

/// Shows `text` in the page's message line (empty: none).
pub(super) fn say(text: &str) {
    if let Ok(d) = document()
        && let Some(el) = d.get_element_by_id("message")
    {
        el.set_text_content(Some(text));
    }
    mark("message", text);
}

/// An error shown in the page.
pub(super) fn failed(e: &anyhow::Error) {
    let text = format!("{e:#}");
    web_sys::console::error_1(&text.clone().into());
    say(&text);
    mark("state", "error");
    FAILED.set(true);
}

/// The image's progress, each frame, and its size (`data-image`, `WxH`:
/// the canvas has the page's size, the image is fitted into it). An error
/// stays the page's state (the last scene still shown) until the next
/// scene is opened.
pub(super) fn progress(
    passes: u32,
    target: u32,
    in_flight: u32,
    (w, h): (u32, u32),
    message: &str,
) {
    let state = if passes >= target && in_flight == 0 {
        "converged"
    } else {
        "running"
    };
    if !FAILED.get() {
        mark("state", state);
    }
    let (painted, done) = COUNTS.get();
    COUNTS.set((painted + 1, done));
    mark("painted", &(painted + 1).to_string());
    mark("passes", &passes.to_string());
    mark("target", &target.to_string());
    mark("image", &format!("{w}x{h}"));
    let changed = SHOWN.with(|s| {
        let mut s = s.borrow_mut();
        let changed = *s != message;
        if changed {
            message.clone_into(&mut s);
        }
        changed
    });
    if changed && !message.is_empty() {
        say(message);
    }
}

/// A frame's GPU work done.
pub(super) fn frame_done() {
    let (painted, done) = COUNTS.get();
    COUNTS.set((painted, done + 1));
    mark("done", &(done + 1).to_string());
}

/// The first image shown, `seconds` after its scene was loaded: logged and
/// marked, with the time since the page began to load.
pub(super) fn first_frame(seconds: f64) {
    let since_start = web_sys::window()
        .and_then(|w| w.performance())
        .map(|p| p.now())
        .unwrap_or(0.0);
    mark("first-frame-ms", &format!("{since_start:.0}"));
    web_sys::console::log_1(
        &format!(
            "first frame {seconds:.2} s after loading the scene, {:.2} s after the page began",
            since_start / 1e3
        )
        .into(),
    );
}

/// The page's canvas (`#view`).
pub(super) fn canvas() -> Result<web_sys::HtmlCanvasElement> {
    document()?
        .get_element_by_id("view")
        .and_then(|e| e.dyn_into().ok())
        .ok_or_else(|| anyhow!("the page has no canvas #view"))
}

/// Offers `bytes` as a download named `name`.
fn download(name: &str, mime: &str, bytes: &[u8]) -> Result<()> {
    let parts = js_sys::Array::of1(&js_sys::Uint8Array::from(bytes));
    let opts = web_sys::BlobPropertyBag::new();
    opts.set_type(mime);
    let blob = web_sys::Blob::new_with_u8_array_sequence_and_options(&parts, &opts).map_err(js)?;
    let url = web_sys::Url::create_object_url_with_blob(&blob).map_err(js)?;
    let a: web_sys::HtmlAnchorElement = document()?
        .create_element("a")
        .map_err(js)?
        .dyn_into()
        .map_err(|_| anyhow!("not an anchor"))?;
    a.set_href(&url);
    a.set_download(name);
    a.click();
    // The download has its own reference to the blob once started.
    let revoke = Closure::once_into_js(move || {
        let _ = web_sys::Url::revoke_object_url(&url);
    });
    if let Some(w) = web_sys::window() {
        let _ =
            w.set_timeout_with_callback_and_timeout_and_arguments_0(revoke.unchecked_ref(), 60_000);
    }
    mark("download", name);
    Ok(())
}

/// Downloads the view as a scene file, `<stem>_view.toml`, its paths
/// relative to the site's scene folder (so that it renders from the
/// repository's `configs/`). Returns its name.
pub(super) fn save(session: &Session, state: &ViewState) -> Result<String> {
    let stem = session.stem();
    let name = format!("{stem}_view.toml");
    let base = crate::files::folder(&session.config).join(format!("{stem}_view"));
    let text = session.saved_text(state, &base, true)?;
    let text = format!(
        "# A view of {stem} saved by blackhole's web viewer; in the repository's\n\
         # configs/ folder, render it with\n#   blackhole render configs/{name}\n{text}"
    );
    download(&name, "text/plain", text.as_bytes())?;
    Ok(name)
}

/// Downloads the image shown, `frame`'s pixels, as the PNG `name` once
/// the GPU has read it back.
pub(super) fn screenshot(prepared: &Prepared<'_>, frame: ViewFrame, name: String) -> Result<()> {
    let (w, h) = (frame.width, frame.height);
    prepared.read_view_later(w, h, move |rgb| {
        let png = rgb.map_err(anyhow::Error::from).and_then(|rgb| {
            let mut out = Vec::new();
            image::RgbImage::from_raw(w, h, rgb)
                .ok_or_else(|| anyhow!("the view read back has the wrong size"))?
                .write_to(&mut std::io::Cursor::new(&mut out), image::ImageFormat::Png)?;
            Ok(out)
        });
        // Said, but not the page's state: the viewer goes on.
        if let Err(e) = png.and_then(|png| download(&name, "image/png", &png)) {
            say(&format!("{:#}", e.context("screenshot failed")));
        }
    })?;
    Ok(())
}

/// A scene begins to load: the page says so and forgets an earlier error.
pub(super) fn loading() {
    say("loading...");
    mark("state", "loading");
    FAILED.set(false);
}

/// Sends `Event::Done` to the viewer once the GPU has done the work
/// submitted so far (ask after the frame's last submission).
pub(super) fn when_done(gpu: &crate::gpu::Gpu, proxy: EventLoopProxy<Event>) {
    let (tx, rx) = futures_channel::oneshot::channel();
    gpu.queue().on_submitted_work_done(move || {
        let _ = tx.send(());
    });
    wasm_bindgen_futures::spawn_local(async move {
        if rx.await.is_ok() {
            let _ = proxy.send_event(Event::Done);
        }
    });
}
