//! The viewer in a web page (wasm32, WebGPU): the scene's files fetched
//! over HTTP into [`crate::inputs`] and the viewer started in the page's
//! canvas (page.rs: what the page shows and offers, for the viewer too).
//!
//! The page (`index.html`) calls the exported functions: [`open_scene`]
//! for a scene of the site, [`open_text`] for a scene pasted or dropped
//! into it, [`save_view`] and [`take_screenshot`] for its buttons.

use super::Session;
use super::event::Event;
use super::page::{failed, js, loading, say};
use crate::config::{Override, SceneConfig};
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
}

/// Files fetched at once while loading a scene.
const FETCHES: usize = 6;

/// The name a scene pasted into the page goes by (in the site's scene
/// folder, so that its relative paths resolve like a shipped scene's).
const PASTED: &str = "/configs/pasted.toml";

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
    loading();
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

/// Set up once the module loads: panics go to the console and the page.
#[wasm_bindgen(start)]
pub fn start() {
    std::panic::set_hook(Box::new(|info| {
        failed(&anyhow!("the viewer stopped: {info}"));
    }));
}
