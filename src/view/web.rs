//! The viewer in a web page (wasm32, WebGPU): the scene's files fetched
//! over HTTP into [`crate::inputs`], the viewer's window made in the
//! page's canvas, and what the page shows and offers: the state of the
//! image (as attributes of `<body>`, for people and for tests), errors,
//! the saved view and the screenshot as downloads.
//!
//! The page (`index.html`) calls the exported functions: [`open_scene`]
//! for a scene of the site, [`open_text`] for a scene pasted or dropped
//! into it, [`save_view`] and [`take_screenshot`] for its buttons.

use super::Session;
use super::event::Event;
use super::state::ViewState;
use crate::config::{Override, SceneConfig};
use crate::gpu::{Prepared, ViewFrame};
use anyhow::{Context, Result, anyhow};
use std::cell::RefCell;
use std::path::{Path, PathBuf};
use wasm_bindgen::JsCast;
use wasm_bindgen::prelude::*;
use winit::event_loop::EventLoopProxy;

thread_local! {
    /// The running viewer, once a scene has loaded.
    static VIEWER: RefCell<Option<EventLoopProxy<Event>>> = const { RefCell::new(None) };
    /// Scene loads begun: a load that another has overtaken is dropped.
    static LOADS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
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

/// Files fetched at once while loading a scene.
const FETCHES: usize = 6;

/// The name a scene pasted into the page goes by (in the site's scene
/// folder, so that its relative paths resolve like a shipped scene's).
const PASTED: &str = "/configs/pasted.toml";

fn document() -> Result<web_sys::Document> {
    web_sys::window()
        .and_then(|w| w.document())
        .ok_or_else(|| anyhow!("no document"))
}

fn js(e: JsValue) -> anyhow::Error {
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
fn say(text: &str) {
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

/// The bytes at `path` on the site (from its root, which is the page's
/// folder).
async fn fetch(path: &Path) -> Result<Vec<u8>> {
    let mut url = String::from(".");
    for part in path.components() {
        if let std::path::Component::Normal(p) = part {
            url.push('/');
            url.push_str(&String::from(js_sys::encode_uri_component(
                &p.to_string_lossy(),
            )));
        }
    }
    let win = web_sys::window().ok_or_else(|| anyhow!("no window"))?;
    let resp = wasm_bindgen_futures::JsFuture::from(win.fetch_with_str(&url))
        .await
        .map_err(js)
        .with_context(|| format!("cannot fetch {url}"))?;
    let resp: web_sys::Response = resp.dyn_into().map_err(|_| anyhow!("not a response"))?;
    if !resp.ok() {
        anyhow::bail!(
            "cannot fetch {url}: HTTP {} {}",
            resp.status(),
            resp.status_text()
        );
    }
    let buf = wasm_bindgen_futures::JsFuture::from(resp.array_buffer().map_err(js)?)
        .await
        .map_err(js)?;
    Ok(js_sys::Uint8Array::new(&buf).to_vec())
}

/// Loads the scene at `path` on the site (`text` if given, else fetched)
/// with `overrides`: checked as the command line checks it, its files
/// fetched, then checked for the GPU.
async fn load(path: &Path, text: Option<String>, overrides: Vec<Override>) -> Result<Session> {
    let text = match text {
        Some(t) => t,
        None => String::from_utf8(fetch(path).await?)
            .with_context(|| format!("{} is not UTF-8 text", path.display()))?,
    };
    crate::inputs::insert(path, text.into_bytes());
    let config = SceneConfig::load(path, &overrides)
        .with_context(|| format!("invalid scene {}", path.display()))?;
    // A spectral set's manifest names more files: until nothing is new.
    for _ in 0..4 {
        let missing: Vec<(String, PathBuf)> = crate::files::scene_inputs(&config)
            .into_iter()
            .filter(|(_, p)| !crate::inputs::fetched(p))
            .collect();
        if missing.is_empty() {
            break;
        }
        for batch in missing.chunks(FETCHES) {
            let got = futures_util::future::join_all(batch.iter().map(|(_, p)| fetch(p))).await;
            for ((key, p), bytes) in batch.iter().zip(got) {
                let bytes = bytes.with_context(|| format!("{key} = {}", p.display()))?;
                crate::inputs::insert(p, bytes);
            }
        }
    }
    Session::open(path, overrides, PathBuf::new())
}

/// Views `session`: in the running viewer, or starts it.
fn show(session: Session) -> Result<()> {
    let running = VIEWER.with(|v| v.borrow().clone());
    match running {
        Some(proxy) => proxy
            .send_event(Event::Open(Box::new(session)))
            .map_err(|_| anyhow!("the viewer has stopped: reload the page")),
        None => {
            let proxy = super::app::run_in_page(session)?;
            VIEWER.with(|v| *v.borrow_mut() = Some(proxy));
            Ok(())
        }
    }
}

/// Runs `f`'s loading and viewing, the outcome shown in the page; a load
/// overtaken by a later one (a slower scene chosen first) is dropped.
async fn opened(f: impl std::future::Future<Output = Result<Session>>) {
    let this = LOADS.get() + 1;
    LOADS.set(this);
    say("loading...");
    mark("state", "loading");
    FAILED.set(false);
    let loaded = f.await;
    if LOADS.get() != this {
        return;
    }
    match loaded.and_then(show) {
        Ok(()) => say(""),
        Err(e) => failed(&e),
    }
}

/// The site path of a scene named in the page: a bare name is a shipped
/// scene (`quick` is `/configs/quick.toml`).
fn scene_path(name: &str) -> PathBuf {
    let name = name.trim_start_matches("./");
    if name.contains('/') || name.ends_with(".toml") {
        Path::new("/").join(name.trim_start_matches('/'))
    } else {
        PathBuf::from(format!("/configs/{name}.toml"))
    }
}

/// Overrides from `key=value` and `!key` (unset) strings.
fn overrides(list: &[String]) -> Result<Vec<Override>> {
    list.iter()
        .map(|o| match o.strip_prefix('!') {
            Some(key) => Override::unset(key),
            None => Override::parse(o),
        })
        .collect::<Result<_, _>>()
        .map_err(anyhow::Error::from)
}

/// Opens the site's scene `name` (see [`scene_path`]) with overrides
/// (`key=value`, or `!key` to unset).
#[wasm_bindgen]
pub async fn open_scene(name: String, sets: Vec<String>) {
    opened(async {
        let o = overrides(&sets)?;
        load(&scene_path(&name), None, o).await
    })
    .await
}

/// Opens scene text pasted or dropped into the page, as a scene in the
/// site's scene folder.
#[wasm_bindgen]
pub async fn open_text(text: String, sets: Vec<String>) {
    opened(async {
        let o = overrides(&sets)?;
        load(Path::new(PASTED), Some(text), o).await
    })
    .await
}

fn send(event: Event) {
    let sent = VIEWER.with(|v| v.borrow().as_ref().map(|p| p.send_event(event).is_ok()));
    if sent != Some(true) {
        say("no scene is being viewed");
    }
}

/// Downloads the view as a scene file.
#[wasm_bindgen]
pub fn save_view() {
    send(Event::Save);
}

/// Presses one of the viewer's keys (the page's buttons for the physics
/// switches, the clock and the help).
#[wasm_bindgen]
pub fn press(key: String) {
    send(Event::Key(key));
}

/// Downloads the image shown as a PNG.
#[wasm_bindgen]
pub fn take_screenshot() {
    send(Event::Screenshot);
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

/// Set up once the module loads: panics go to the console and the page.
#[wasm_bindgen(start)]
pub fn start() {
    std::panic::set_hook(Box::new(|info| {
        failed(&anyhow!("the viewer stopped: {info}"));
    }));
}
