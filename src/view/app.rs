//! The viewer's window: winit for the window and input, the GPU backend
//! for the image (one sample per pixel per frame, accumulated while the
//! view holds still, bloomed, tone-mapped and encoded on the GPU into a
//! texture that is drawn into the window without leaving the GPU), egui
//! for the overlay and help.

use super::Session;
use super::event::Event;
use super::state::{Toggle, ViewState};
use crate::film::Stats;
use crate::gpu::{Gpu, Prepared, ViewFrame};
use crate::scene::Scene;
use anyhow::{Context, Result, anyhow};
use std::sync::Arc;
#[cfg(not(target_arch = "wasm32"))]
use std::time::Instant;
#[cfg(target_arch = "wasm32")]
use web_time::Instant;
use winit::application::ApplicationHandler;
#[cfg(not(target_arch = "wasm32"))]
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop, EventLoopProxy};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

/// Samples a still view accumulates when the scene asks for one.
pub const STILL_SAMPLES: u32 = 64;

/// The frame rate a moving view keeps by lowering its resolution.
const MOVING_FPS: f64 = 30.0;

/// The most a moving view's sides are divided by.
const MAX_PREVIEW_SCALE: u32 = 8;

/// The keys and what they do, for the help window and the user guide.
pub const CONTROLS: &[(&str, &str)] = &[
    ("left drag", "orbit the camera about the hole"),
    ("right drag", "pan: move the point looked at"),
    ("wheel", "distance from the hole (logarithmic)"),
    ("shift + wheel", "field of view"),
    ("m", "ray model: gr / seed"),
    ("[ and ]", "spin down / up (tenths, then 0.99 and 0.998)"),
    ("l", "spectral rendering on / off"),
    ("z", "frequency shift on / off"),
    ("d", "Doppler shift on / off"),
    ("b", "beaming on / off"),
    (
        "- and =",
        "an observed scene's frequency down / up (a third of an octave)",
    ),
    ("space", "play / pause the disk's rotation"),
    (". and ,", "rotation faster / slower (x2)"),
    ("r", "reset the camera and the clock"),
    ("p", "screenshot: PNG and EXR at the scene's quality"),
    ("s", "save the view as a scene file"),
    ("i", "overlay on / off"),
    ("h", "this help"),
    ("q or Esc", "quit"),
];

/// The controls as this build has them: in the browser the screenshot and
/// the saved view are downloads, and nothing quits.
fn controls() -> Vec<(&'static str, &'static str)> {
    CONTROLS
        .iter()
        .filter_map(|&(k, w)| {
            if !cfg!(target_arch = "wasm32") {
                return Some((k, w));
            }
            match k {
                "p" => Some((k, "screenshot: the image shown, as a PNG download")),
                "s" => Some((k, "save the view as a scene file (a download)")),
                "q or Esc" => None,
                _ => Some((k, w)),
            }
        })
        .collect()
}

/// Text size that lets `rows` lines of about `chars` characters (and some
/// padding) fit in `area`, at most the usual 11 to 13 points.
fn fitting_size(area: egui::Rect, rows: usize, chars: usize, most: f32) -> f32 {
    let by_height = (area.height() - 40.0) / (rows as f32 * 1.6);
    let by_width = (area.width() - 30.0) / (chars as f32 * 0.62);
    by_height.min(by_width).clamp(6.0, most)
}

/// The image to draw: the GPU texture's id, the size of the image in it
/// and the texture's whole size (a preview fills its top-left corner).
#[derive(Clone, Copy)]
struct Shown {
    id: egui::TextureId,
    size: [u32; 2],
    texture: [u32; 2],
}

/// The frame's interface: the image fitted to the window, the overlay's
/// lines and the help's table, each sized and wrapped to stay inside the
/// window however small it is.
fn draw_ui(
    ctx: &egui::Context,
    image: Option<Shown>,
    lines: &[String],
    overlay: bool,
    help: &mut bool,
) {
    let area = ctx.viewport_rect();
    if let Some(Shown {
        id,
        size: [w, h],
        texture: [tw, th],
    }) = image
    {
        // The image fitted to the window, centred.
        let k = (area.width() / w as f32).min(area.height() / h as f32);
        let size = egui::vec2(w as f32 * k, h as f32 * k);
        let rect = egui::Rect::from_center_size(area.center(), size);
        ctx.layer_painter(egui::LayerId::background()).image(
            id,
            rect,
            egui::Rect::from_min_max(
                egui::pos2(0.0, 0.0),
                egui::pos2(w as f32 / tw as f32, h as f32 / th as f32),
            ),
            egui::Color32::WHITE,
        );
    }
    if overlay {
        // Wrapped at the window's width; small windows get smaller text.
        let width = (area.width() - 24.0).max(40.0);
        let size = fitting_size(area, 2 * lines.len(), 48, 11.0);
        egui::Area::new(egui::Id::unique("overlay"))
            .fixed_pos(egui::pos2(6.0, 6.0))
            .show(ctx, |ui| {
                egui::Frame::popup(ui.style())
                    .fill(egui::Color32::from_black_alpha(170))
                    .show(ui, |ui| {
                        ui.set_max_width(width);
                        ui.style_mut().wrap_mode = Some(egui::TextWrapMode::Wrap);
                        for l in lines {
                            ui.label(
                                egui::RichText::new(l)
                                    .monospace()
                                    .size(size)
                                    .color(egui::Color32::from_gray(230)),
                            );
                        }
                    });
            });
    }
    let controls = controls();
    let longest = controls
        .iter()
        .map(|(k, w)| k.len() + w.len() + 2)
        .max()
        .unwrap_or(40);
    let size = fitting_size(area, controls.len() + 2, longest, 13.0);
    egui::Window::new("Controls")
        .open(help)
        .collapsible(false)
        .resizable(false)
        .title_bar(false)
        .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO)
        .max_width(area.width() - 8.0)
        .show(ctx, |ui| {
            // Sized to fit, so nothing wraps; rows as tall as their text
            // (egui's rows are at least a button's height).
            ui.style_mut().wrap_mode = Some(egui::TextWrapMode::Extend);
            ui.spacing_mut().interact_size.y = size * 1.25;
            ui.spacing_mut().item_spacing = egui::vec2(size * 0.6, size * 0.15);
            ui.label(
                egui::RichText::new("controls (h closes)")
                    .strong()
                    .size(size),
            );
            egui::Grid::new("controls")
                .striped(true)
                .spacing([size * 0.6, size * 0.15])
                .show(ui, |ui| {
                    for (key, what) in &controls {
                        ui.label(egui::RichText::new(*key).monospace().size(size));
                        ui.label(egui::RichText::new(*what).size(size));
                        ui.end_row();
                    }
                });
        });
}

/// Opens the window on `session` and runs until it is closed.
#[cfg(not(target_arch = "wasm32"))]
pub fn run(session: Session) -> Result<()> {
    let event_loop = EventLoop::<Event>::with_user_event().build().map_err(|e| {
        anyhow!(
            "cannot open a window ({e}): the viewer needs a display (on Linux an X server: \
             set DISPLAY, or run it under xvfb-run)"
        )
    })?;
    event_loop.set_control_flow(ControlFlow::Wait);
    // The wheel buttons' raw events (see `App::wheel_button`), focused or
    // not.
    event_loop.listen_device_events(winit::event_loop::DeviceEvents::Always);
    let mut app = App::new(session, event_loop.create_proxy());
    event_loop
        .run_app(&mut app)
        .map_err(|e| anyhow!("the window's event loop failed: {e}"))?;
    match app.failed {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// Runs the viewer in the page's canvas on `session`; the page then
/// talks to it through `proxy`'s events.
#[cfg(target_arch = "wasm32")]
pub fn run_in_page(session: Session) -> Result<EventLoopProxy<Event>> {
    use winit::platform::web::EventLoopExtWebSys;
    let event_loop = EventLoop::<Event>::with_user_event()
        .build()
        .map_err(|e| anyhow!("cannot start the page's event loop: {e}"))?;
    event_loop.set_control_flow(ControlFlow::Wait);
    let proxy = event_loop.create_proxy();
    event_loop.spawn_app(App::new(session, proxy.clone()));
    Ok(proxy)
}

/// Samples a still view of `session`'s scene accumulates: its own, or
/// [`STILL_SAMPLES`] where it asks for one.
fn still_target(session: &Session) -> u32 {
    match session.original.image.samples {
        n if n > 1 => n,
        _ => STILL_SAMPLES,
    }
}

/// The scale and window size that show a `w` x `h` image whole: its own
/// size, scaled down to fit the screen if need be. (The page's canvas
/// has the size the page gives it.)
#[cfg(not(target_arch = "wasm32"))]
fn fitted(event_loop: &ActiveEventLoop, w: u32, h: u32) -> (f64, PhysicalSize<u32>) {
    let fit = event_loop
        .primary_monitor()
        .or_else(|| event_loop.available_monitors().next())
        .map_or(1.0, |m| {
            let s = m.size();
            (0.9 * s.width as f64 / w as f64)
                .min(0.9 * s.height as f64 / h as f64)
                .min(1.0)
        });
    let size = PhysicalSize::new(
        ((w as f64 * fit).round() as u32).max(1),
        ((h as f64 * fit).round() as u32).max(1),
    );
    (fit, size)
}

/// What the window draws with.
struct Gfx {
    window: Arc<Window>,
    gpu: &'static Gpu,
    surface: wgpu::Surface<'static>,
    surface_config: wgpu::SurfaceConfiguration,
    egui: egui_winit::State,
    painter: egui_wgpu::Renderer,
    /// The prepared scene's display texture as egui knows it, and the
    /// filter it is drawn with.
    texture: Option<(egui::TextureId, wgpu::FilterMode)>,
    scene: Scene,
    prepared: Prepared<'static>,
}

struct App {
    session: Session,
    /// For the browser's callbacks (the desktop's calls return at once).
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
    proxy: EventLoopProxy<Event>,
    /// The window while the browser opens the GPU.
    #[cfg(target_arch = "wasm32")]
    opening: Option<Arc<Window>>,
    /// In the browser: frames whose GPU work is submitted and not done
    /// (one at a time, so that input stays ahead of the GPU), and when the
    /// last began and whether it was full size.
    in_flight: u32,
    submitted: Option<(Instant, bool)>,
    state: ViewState,
    /// The switches the current scene was built with.
    built: ViewState,
    /// Samples a still view accumulates.
    target: u32,
    gfx: Option<Gfx>,
    failed: Option<anyhow::Error>,
    /// The view's samples so far (passes of one sample), their counts,
    /// and the last full-resolution frame.
    passes: u32,
    acc_stats: Option<Stats>,
    full: Option<ViewFrame>,
    /// A reduced-resolution frame shown while the view moves.
    preview: Option<ViewFrame>,
    /// Seconds a full-resolution frame last took: the GPU's own time
    /// where it keeps timestamps, else the wall time of the trace.
    full_pass: f64,
    /// The view needs its camera or clock moved on the GPU.
    moved: bool,
    last_frame: Instant,
    /// Recent frame times, for the frame rate.
    pass_times: Vec<f64>,
    /// The GPU's own time for the last frame (s): trace and display,
    /// where it keeps timestamps.
    device_seconds: Option<f64>,
    /// The pointer's last position in the window.
    cursor: Option<(f64, f64)>,
    drag_left: bool,
    drag_right: bool,
    /// Fingers on a touch screen, by id, where each last was: one orbits,
    /// two pinch the distance.
    touches: Vec<(u64, (f64, f64))>,
    shift: bool,
    overlay: bool,
    help: bool,
    /// The last raw press or release of a wheel button (4 to 7): X11
    /// servers without wheel valuators (Xvfb, xdotool) send a notch as a
    /// press and a release, and winit reports each as a wheel step, so the
    /// release's step is dropped. Real wheels come as valuator motion with
    /// no such raw buttons, and are taken as they come.
    wheel_button: Option<ElementState>,
    /// The last thing written or gone wrong, for the overlay.
    message: String,
    /// When the scene was loaded, until the first frame is shown.
    loaded: Option<Instant>,
}

impl App {
    fn new(session: Session, proxy: EventLoopProxy<Event>) -> App {
        let state = session.start();
        App {
            proxy,
            #[cfg(target_arch = "wasm32")]
            opening: None,
            in_flight: 0,
            submitted: None,
            target: still_target(&session),
            built: state.clone(),
            state,
            session,
            gfx: None,
            failed: None,
            passes: 0,
            acc_stats: None,
            full: None,
            preview: None,
            full_pass: 0.0,
            moved: false,
            last_frame: Instant::now(),
            pass_times: Vec::new(),
            device_seconds: None,
            cursor: None,
            drag_left: false,
            drag_right: false,
            touches: Vec::new(),
            shift: false,
            overlay: true,
            help: false,
            wheel_button: None,
            message: String::new(),
            loaded: Some(Instant::now()),
        }
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, e: anyhow::Error) {
        #[cfg(target_arch = "wasm32")]
        super::page::failed(&e);
        self.failed = Some(e);
        event_loop.exit();
    }

    /// Opens the window and everything that draws into it.
    fn open(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let img = &self.session.original.image;
        let (w, h) = (img.width, img.height);
        let name = self
            .session
            .config
            .file_name()
            .map_or("".into(), |n| n.to_string_lossy().into_owned());
        #[cfg(not(target_arch = "wasm32"))]
        let attrs = {
            let (fit, size) = fitted(event_loop, w, h);
            Window::default_attributes()
                .with_title(format!(
                    "blackhole view: {name}, {w} x {h} shown at {:.0}%",
                    fit * 100.0
                ))
                .with_inner_size(size)
        };
        // The page lays the canvas out (it fills the window below the
        // controls) and the image is fitted into it, as into a resized
        // desktop window.
        #[cfg(target_arch = "wasm32")]
        let attrs = {
            use winit::platform::web::WindowAttributesExtWebSys;
            Window::default_attributes()
                .with_title(format!("blackhole view: {name}, {w} x {h}"))
                .with_canvas(Some(super::page::canvas()?))
        };
        let window = Arc::new(
            event_loop
                .create_window(attrs)
                .context("cannot open the viewer's window")?,
        );
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
                Box::new(event_loop.owned_display_handle()),
            ));
        let surface = instance.create_surface(window.clone()).map_err(|e| {
            if cfg!(target_arch = "wasm32") {
                anyhow!("the browser's WebGPU cannot draw into the page's canvas ({e})")
            } else {
                anyhow!(
                    "no GPU backend can draw into the window ({e}); if WGPU_BACKEND is set, it \
                     must name a backend this machine has (Vulkan on Linux: apt-get install \
                     mesa-vulkan-drivers libvulkan1 for software Vulkan)"
                )
            }
        })?;
        #[cfg(not(target_arch = "wasm32"))]
        {
            let gpu = Gpu::for_surface(&instance, &surface)?;
            self.attach(window, surface, gpu)
        }
        #[cfg(target_arch = "wasm32")]
        {
            let proxy = self.proxy.clone();
            wasm_bindgen_futures::spawn_local(async move {
                let gpu = Gpu::for_surface_async(&instance, &surface).await;
                let _ = proxy.send_event(Event::Gpu(Box::new(gpu.map(|g| (g, surface)))));
            });
            self.opening = Some(window);
            Ok(())
        }
    }

    /// Everything that draws into `window` once the GPU is open.
    fn attach(
        &mut self,
        window: Arc<Window>,
        surface: wgpu::Surface<'static>,
        gpu: Gpu,
    ) -> Result<()> {
        let gpu: &'static Gpu = Box::leak(Box::new(gpu));
        let caps = surface.get_capabilities(gpu.adapter());
        // egui and the image are sRGB-encoded already: a linear target.
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| !f.is_srgb())
            .or_else(|| caps.formats.first().copied())
            .ok_or_else(|| anyhow!("the window's surface offers no pixel format"))?;
        let size = window.inner_size();
        let surface_config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes[0],
            color_space: wgpu::SurfaceColorSpace::Auto,
            view_formats: vec![],
        };
        surface.configure(gpu.device(), &surface_config);
        let ctx = egui::Context::default();
        let egui = egui_winit::State::new(
            ctx,
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(gpu.device().limits().max_texture_dimension_2d as usize),
        );
        let painter = egui_wgpu::Renderer::new(
            gpu.device(),
            format,
            egui_wgpu::RendererOptions {
                // The image is shown as rendered, without noise added.
                dithering: false,
                ..Default::default()
            },
        );
        let scene = self
            .session
            .scene(&self.state, None, Some(self.target), true)?;
        let prepared = gpu.prepare_passes(&scene, 1)?;
        self.gfx = Some(Gfx {
            window,
            gpu,
            surface,
            surface_config,
            egui,
            painter,
            texture: None,
            scene,
            prepared,
        });
        Ok(())
    }

    /// Starts the view's samples again.
    fn restart(&mut self) {
        self.passes = 0;
        self.acc_stats = None;
        self.full = None;
    }

    /// Brings the GPU's scene to the state: a new scene for new switches,
    /// else the camera and clock moved. A view the scene cannot take (a
    /// switch the GPU cannot render, a camera with no view) is undone and
    /// said in the overlay.
    fn sync(&mut self) -> Result<()> {
        if !self.state.changed_physics(&self.built).is_empty() {
            let scene = self
                .session
                .scene(&self.state, None, Some(self.target), true)
                .and_then(|s| {
                    crate::gpu::check_supported(&s)?;
                    Ok(s)
                });
            match scene {
                Ok(scene) => {
                    let gfx = self.gfx.as_mut().expect("open");
                    gfx.prepared = gfx.gpu.prepare_passes(&scene, 1)?;
                    gfx.scene = scene;
                    // The new scene draws into a texture of its own.
                    if let Some((id, _)) = gfx.texture.take() {
                        gfx.painter.free_texture(&id);
                    }
                    self.built = self.state.clone();
                    self.moved = false;
                    self.restart();
                }
                Err(e) => {
                    self.message = format!("{e:#}");
                    let (pose, time) = (self.state.pose, self.state.time);
                    self.state = ViewState {
                        pose,
                        time,
                        playing: self.state.playing,
                        speed: self.state.speed,
                        ..self.built.clone()
                    };
                }
            }
        }
        if self.moved {
            self.moved = false;
            let gfx = self.gfx.as_mut().expect("open");
            match gfx.scene.set_view(&self.state.pose, self.state.time) {
                Ok(()) => {
                    gfx.prepared.set_frame(&gfx.scene)?;
                    self.built.pose = self.state.pose;
                    self.built.time = self.state.time;
                    self.restart();
                }
                Err(e) => {
                    self.message = e.to_string();
                    self.state.pose = self.built.pose;
                }
            }
        }
        Ok(())
    }

    /// One more sample of the view, if it wants one, traced, added up,
    /// bloomed and encoded on the GPU. While the view moves, full
    /// resolution whenever a full frame (trace and display) fits a frame at
    /// [`MOVING_FPS`]; else one sample of a smaller image (each side
    /// divided by the least whole factor that should keep the rate, at
    /// most [`MAX_PREVIEW_SCALE`]); accumulation starts once it is still.
    fn refine(&mut self, moving: bool) -> Result<()> {
        let scale = if moving {
            ((self.full_pass * MOVING_FPS).sqrt().ceil() as u32).clamp(1, MAX_PREVIEW_SCALE)
        } else {
            1
        };
        if (scale == 1 && self.passes >= self.target) || self.in_flight > 0 {
            return Ok(());
        }
        let gfx = self.gfx.as_mut().expect("open");
        let t0 = Instant::now();
        // The browser runs the frame after this returns: it is timed when
        // the GPU says it is done (`Event::Done`).
        let web = cfg!(target_arch = "wasm32");
        if web {
            // The GPU is asked when it is done once the frame is submitted
            // (`frame`, after `paint`).
            self.in_flight += 1;
            self.submitted = Some((t0, scale == 1));
        }
        if scale > 1 {
            let frame = gfx.prepared.view_pass(0, 1, scale, true)?;
            self.device_seconds = gfx.prepared.device_seconds();
            if !web {
                self.timed(t0);
            }
            self.preview = Some(frame);
            self.restart();
        } else {
            let frame = gfx
                .prepared
                .view_pass(self.passes, 1, 1, self.passes == 0)?;
            self.device_seconds = gfx.prepared.device_seconds();
            if !web {
                let wall = self.timed(t0);
                self.full_pass = self.device_seconds.unwrap_or(wall);
            }
            self.preview = None;
            self.acc_stats = Some(match self.acc_stats {
                None => frame.stats,
                Some(s) => s + frame.stats,
            });
            self.full = Some(frame);
            self.passes += 1;
        }
        Ok(())
    }

    /// Records a pass that began at `t0` for the frame rate; its seconds.
    fn timed(&mut self, t0: Instant) -> f64 {
        let t = t0.elapsed().as_secs_f64();
        self.pass_times.push(t);
        if self.pass_times.len() > 10 {
            self.pass_times.remove(0);
        }
        t
    }

    /// The image to draw: the display's texture registered with egui
    /// (again when the scene or the filter changed); drawn pixel for
    /// pixel where the window has the image's size, else filtered.
    fn shown(&mut self) -> Result<Option<Shown>> {
        let Some(frame) = self.preview.or(self.full) else {
            return Ok(None);
        };
        let gfx = self.gfx.as_mut().expect("open");
        let window = gfx.window.inner_size();
        let filter = if (window.width, window.height) == (frame.width, frame.height) {
            wgpu::FilterMode::Nearest
        } else {
            wgpu::FilterMode::Linear
        };
        let view = gfx.prepared.view_texture()?;
        let device = gfx.gpu.device();
        let id = match gfx.texture {
            Some((id, f)) if f == filter => id,
            Some((id, _)) => {
                gfx.painter
                    .update_egui_texture_from_wgpu_texture(device, &view, filter, id);
                id
            }
            None => gfx.painter.register_native_texture(device, &view, filter),
        };
        gfx.texture = Some((id, filter));
        let img = gfx.scene.image();
        Ok(Some(Shown {
            id,
            size: [frame.width, frame.height],
            texture: [img.width, img.height],
        }))
    }

    fn overlay_lines(&self) -> Vec<String> {
        let s = &self.state;
        let fps = if self.pass_times.is_empty() {
            0.0
        } else {
            self.pass_times.len() as f64 / self.pass_times.iter().sum::<f64>()
        };
        let progress = match &self.preview {
            Some(p) => format!("moving: preview at {}x{}", p.width, p.height),
            None => format!("{} of {} samples", self.passes, self.target),
        };
        // The trace and display of the last frame: by the GPU's clock, or
        // on devices without timestamps (CPU devices, whose time is the
        // host's) by the host's.
        let gpu = match (self.device_seconds, self.pass_times.last()) {
            (Some(t), _) => format!(" (GPU {:.2} ms a frame)", t * 1e3),
            (None, Some(t)) => format!(" ({:.1} ms a frame)", t * 1e3),
            (None, None) => String::new(),
        };
        let mut lines = vec![
            format!("{fps:.1} frames/s{gpu}, {progress}"),
            format!(
                "distance {:.3} r_s, elevation {:.1} deg, fov {:.1} deg",
                s.distance(),
                s.elevation(),
                s.pose.fov
            ),
            format!(
                "model {}{}, {}",
                s.model.name(),
                if s.spin != 0.0 {
                    format!(" spin a = {}", s.spin)
                } else {
                    String::new()
                },
                if s.spectral {
                    format!(
                        "spectral: shift {}, Doppler {}, beaming {}",
                        on(s.shift),
                        on(s.doppler),
                        on(s.beaming)
                    )
                } else {
                    "RGB".into()
                }
            ),
        ];
        if let (Some(&nu), Some(look)) = (
            s.frequencies.first(),
            crate::colormap::RadioLook::of(&self.session.original),
        ) {
            lines.push(format!(
                "observed at {}: {}",
                crate::config::quantity::frequency_text(nu),
                look.describe()
            ));
        }
        if s.spectral
            && let Some(stats) = self.preview.map(|p| p.stats).or(self.acc_stats)
            && stats.g_max >= stats.g_min
        {
            lines.push(format!(
                "g on the disk {:.3} to {:.3}",
                stats.g_min, stats.g_max
            ));
        }
        let unit = s.r_s / crate::units::C;
        lines.push(format!(
            "t = {:.1} s ({:.1} r_s/c), rotation {} ({:.3} s per s)",
            s.time,
            s.time / unit,
            if s.playing { "on" } else { "paused" },
            s.speed
        ));
        if !self.message.is_empty() {
            lines.push(self.message.clone());
        }
        lines.push("h: help".into());
        lines
    }

    /// Draws the image and the overlay, and presents the frame.
    fn paint(&mut self) -> Result<()> {
        let lines = self.overlay_lines();
        let (overlay, mut help) = (self.overlay, self.help);
        let image = self.shown()?;
        let gfx = self.gfx.as_mut().expect("open");
        let raw = gfx.egui.take_egui_input(&gfx.window);
        let ctx = gfx.egui.egui_ctx().clone();
        let full = ctx.run_pass(raw, |ctx| draw_ui(ctx, image, &lines, overlay, &mut help));
        self.help = help;
        // egui's own animations (the help fading in) want the next frame.
        let again = full
            .viewport_output
            .get(&egui::ViewportId::ROOT)
            .is_some_and(|v| v.repaint_delay.is_zero());
        gfx.egui
            .handle_platform_output(&gfx.window, full.platform_output);
        let jobs = ctx.tessellate(full.shapes, full.pixels_per_point);
        let (device, queue) = (gfx.gpu.device(), gfx.gpu.queue());
        for (id, deltas) in &full.textures_delta.set {
            for delta in deltas {
                gfx.painter.update_texture(device, queue, *id, delta);
            }
        }
        let frame = match gfx.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f)
            | wgpu::CurrentSurfaceTexture::Suboptimal(f) => f,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                gfx.surface.configure(device, &gfx.surface_config);
                gfx.window.request_redraw();
                return Ok(());
            }
            // Nothing to draw into this time.
            _ => return Ok(()),
        };
        let view = frame
            .texture
            .create_view(&wgpu::TextureViewDescriptor::default());
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [gfx.surface_config.width, gfx.surface_config.height],
            pixels_per_point: full.pixels_per_point,
        };
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("view"),
        });
        let mut commands = gfx
            .painter
            .update_buffers(device, queue, &mut enc, &jobs, &screen);
        {
            let mut pass = enc
                .begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("view"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &view,
                        resolve_target: None,
                        depth_slice: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                })
                .forget_lifetime();
            gfx.painter.render(&mut pass, &jobs, &screen);
        }
        commands.push(enc.finish());
        queue.submit(commands);
        queue.present(frame);
        for id in &full.textures_delta.free {
            gfx.painter.free_texture(id);
        }
        gfx.gpu.check()?;
        if again {
            gfx.window.request_redraw();
        }
        Ok(())
    }

    fn frame(&mut self) -> Result<()> {
        let now = Instant::now();
        let wall = now.duration_since(self.last_frame).as_secs_f64();
        self.last_frame = now;
        if self.state.playing {
            self.state.advance(wall.min(0.25));
            self.moved = true;
        }
        // Input since the last frame, or the clock, moved the view. In the
        // browser, while the GPU works on the last frame the move waits and
        // that frame stays on screen.
        let moving = self.moved;
        let idle = self.in_flight == 0;
        if idle {
            self.sync()?;
            self.refine(moving)?;
        }
        self.paint()?;
        // A frame submitted (the browser's): asked after its last
        // submission, so that its work is what is waited for.
        #[cfg(target_arch = "wasm32")]
        if idle && self.in_flight > 0 {
            let gfx = self.gfx.as_ref().expect("open");
            super::page::when_done(gfx.gpu, self.proxy.clone());
        }
        // (In the browser the first frame is there when the GPU says so:
        // `done`.)
        #[cfg(not(target_arch = "wasm32"))]
        if self.passes > 0
            && let Some(t0) = self.loaded.take()
        {
            let gfx = self.gfx.as_ref().expect("open");
            eprintln!(
                "viewing on {}: first frame {:.2} s after loading the scene; h shows the controls",
                gfx.gpu.name(),
                t0.elapsed().as_secs_f64()
            );
        }
        let busy = self.passes < self.target || self.state.playing;
        #[cfg(target_arch = "wasm32")]
        {
            let img = self.gfx.as_ref().expect("open").scene.image();
            let size = (img.width, img.height);
            super::page::progress(
                self.passes,
                self.target,
                self.in_flight,
                size,
                &self.message,
            );
        }
        let gfx = self.gfx.as_ref().expect("open");
        // In the browser the GPU's "done" asks for the next frame.
        if busy && self.in_flight == 0 {
            gfx.window.request_redraw();
        }
        Ok(())
    }

    /// A frame's GPU work done (the browser): timed (`user_event` asks for
    /// the next).
    fn done(&mut self) {
        self.in_flight = self.in_flight.saturating_sub(1);
        #[cfg(target_arch = "wasm32")]
        super::page::frame_done();
        if let Some((t0, full)) = self.submitted.take() {
            let t = self.timed(t0);
            if full {
                self.full_pass = t;
                #[cfg(target_arch = "wasm32")]
                if let Some(t0) = self.loaded.take() {
                    super::page::first_frame(t0.elapsed().as_secs_f64());
                }
            }
        }
    }

    /// Writes the view as a scene file (in the browser: downloads it).
    fn save(&mut self) {
        #[cfg(not(target_arch = "wasm32"))]
        {
            self.message = match self.session.save(&self.state) {
                Ok(p) => format!("saved {}", p.display()),
                Err(e) => format!("saving failed: {e:#}"),
            };
            eprintln!("{}", self.message);
        }
        #[cfg(target_arch = "wasm32")]
        {
            self.message = match super::page::save(&self.session, &self.state) {
                Ok(name) => format!("saved {name}"),
                Err(e) => format!("saving failed: {e:#}"),
            };
        }
    }

    /// A screenshot: on the desktop a render at the scene's quality, PNG
    /// and EXR; in the browser the image shown, as a PNG download.
    fn screenshot(&mut self) {
        #[cfg(not(target_arch = "wasm32"))]
        {
            let gpu = self.gfx.as_ref().expect("open").gpu;
            self.message = match self.session.screenshot(&self.state, gpu) {
                Ok(p) => format!("wrote {}", p.display()),
                Err(e) => format!("screenshot failed: {e:#}"),
            };
            eprintln!("{}", self.message);
        }
        #[cfg(target_arch = "wasm32")]
        {
            let Some(frame) = self.full.filter(|_| self.preview.is_none()) else {
                self.message = "screenshot: the view is still moving".into();
                return;
            };
            let gfx = self.gfx.as_ref().expect("open");
            let name = format!("{}_shot.png", self.session.stem());
            self.message = match super::page::screenshot(&gfx.prepared, frame, name.clone()) {
                Ok(()) => format!("saved {name}"),
                Err(e) => format!("screenshot failed: {e:#}"),
            };
        }
    }

    /// Views another scene (opened, so checked for the GPU) in the same
    /// window, made its size on the desktop (the page's canvas keeps the
    /// size the page gives it).
    #[cfg_attr(target_arch = "wasm32", allow(unused_variables))]
    fn open_session(&mut self, event_loop: &ActiveEventLoop, session: Session) -> Result<()> {
        let state = session.start();
        let target = still_target(&session);
        let scene = session.scene(&state, None, Some(target), true)?;
        // What can fail first: on failure the old scene stays as it was.
        let prepared = match &self.gfx {
            Some(gfx) => Some(gfx.gpu.prepare_passes(&scene, 1)?),
            None => None,
        };
        self.target = target;
        if let (Some(gfx), Some(prepared)) = (self.gfx.as_mut(), prepared) {
            #[cfg(not(target_arch = "wasm32"))]
            {
                let img = scene.image();
                let (_, size) = fitted(event_loop, img.width, img.height);
                if let Some(now) = gfx.window.request_inner_size(size) {
                    // Resized at once (else a Resized event follows).
                    gfx.surface_config.width = now.width.max(1);
                    gfx.surface_config.height = now.height.max(1);
                    gfx.surface.configure(gfx.gpu.device(), &gfx.surface_config);
                }
            }
            gfx.prepared = prepared;
            gfx.scene = scene;
            if let Some((id, _)) = gfx.texture.take() {
                gfx.painter.free_texture(&id);
            }
        }
        self.session = session;
        self.built = state.clone();
        self.state = state;
        self.moved = false;
        self.preview = None;
        self.message.clear();
        self.loaded = Some(Instant::now());
        // A frame of the old scene still on the GPU is neither timed nor
        // the new one's first.
        self.submitted = None;
        self.restart();
        Ok(())
    }

    /// A key pressed (not repeated) outside egui.
    fn key(&mut self, event_loop: &ActiveEventLoop, key: &Key) {
        let s = &mut self.state;
        let mut moved = false;
        match key {
            Key::Named(NamedKey::Escape) if !cfg!(target_arch = "wasm32") => event_loop.exit(),
            Key::Named(NamedKey::Space) => {
                s.playing = !s.playing;
                self.last_frame = Instant::now();
            }
            Key::Character(c) => match c.as_str() {
                "q" if !cfg!(target_arch = "wasm32") => event_loop.exit(),
                "m" => s.toggle(Toggle::Model),
                "[" => s.change_spin(false),
                "]" => s.change_spin(true),
                "l" => s.toggle(Toggle::Spectral),
                "z" => s.toggle(Toggle::Shift),
                "d" => s.toggle(Toggle::Doppler),
                "b" => s.toggle(Toggle::Beaming),
                "-" => s.change_frequency(false),
                "=" | "+" => s.change_frequency(true),
                "." | ">" => s.change_speed(true),
                "," | "<" => s.change_speed(false),
                "r" => {
                    s.reset();
                    moved = true;
                }
                "i" => self.overlay = !self.overlay,
                "h" => self.help = !self.help,
                "p" => self.screenshot(),
                "s" => self.save(),
                _ => return,
            },
            _ => return,
        }
        self.moved |= moved;
        if let Some(g) = &self.gfx {
            g.window.request_redraw();
        }
    }

    /// A finger down, moved or lifted: one finger orbits as the left drag
    /// does, two change the distance by the ratio of their spread.
    fn touch(&mut self, t: winit::event::Touch) {
        use winit::event::TouchPhase;
        let p = (t.location.x, t.location.y);
        let spread = |ts: &[(u64, (f64, f64))]| match ts {
            [(_, a), (_, b)] => Some((a.0 - b.0).hypot(a.1 - b.1)),
            _ => None,
        };
        match t.phase {
            TouchPhase::Started => self.touches.push((t.id, p)),
            TouchPhase::Moved => {
                let before = spread(&self.touches);
                let Some(i) = self.touches.iter().position(|(id, _)| *id == t.id) else {
                    return;
                };
                let last = std::mem::replace(&mut self.touches[i].1, p);
                if self.touches.len() == 1 {
                    self.state.orbit(p.0 - last.0, p.1 - last.1);
                    self.moved = true;
                } else if let (Some(a), Some(b)) = (before, spread(&self.touches))
                    && a > 0.0
                    && b > 0.0
                {
                    self.state.pinch(b / a);
                    self.moved = true;
                }
            }
            TouchPhase::Ended | TouchPhase::Cancelled => self.touches.retain(|(id, _)| *id != t.id),
        }
    }

    /// The image pixels per window pixel (the image is fitted).
    fn image_per_window_px(&self) -> f64 {
        let g = self.gfx.as_ref().expect("open");
        let size = g.window.inner_size();
        let img = g.scene.image();
        (img.width as f64 / size.width.max(1) as f64)
            .max(img.height as f64 / size.height.max(1) as f64)
    }
}

fn on(b: bool) -> &'static str {
    if b { "on" } else { "off" }
}

impl ApplicationHandler<Event> for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        #[cfg(target_arch = "wasm32")]
        if self.opening.is_some() {
            return;
        }
        if self.gfx.is_some() {
            return;
        }
        if let Err(e) = self.open(event_loop) {
            self.fail(event_loop, e);
            return;
        }
        if let Some(g) = &self.gfx {
            g.window.request_redraw();
        }
    }

    fn user_event(&mut self, event_loop: &ActiveEventLoop, event: Event) {
        match event {
            Event::Gpu(opened) => {
                #[cfg(target_arch = "wasm32")]
                if let Some(window) = self.opening.take() {
                    let r = (*opened)
                        .map_err(anyhow::Error::from)
                        .and_then(|(gpu, surface)| self.attach(window, surface, gpu));
                    if let Err(e) = r {
                        self.fail(event_loop, e);
                    }
                }
                #[cfg(not(target_arch = "wasm32"))]
                drop(opened);
            }
            Event::Open(session) => {
                if let Err(e) = self.open_session(event_loop, *session) {
                    self.message = format!("{e:#}");
                    #[cfg(target_arch = "wasm32")]
                    super::page::failed(&e);
                }
            }
            Event::Save => self.save(),
            Event::Key(k) => {
                let key = match k.as_str() {
                    " " => Key::Named(NamedKey::Space),
                    _ => Key::Character(k.as_str().into()),
                };
                self.key(event_loop, &key);
            }
            Event::Screenshot => self.screenshot(),
            Event::Done => self.done(),
        }
        // Whatever came, the view may have changed.
        if let Some(g) = &self.gfx {
            g.window.request_redraw();
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(gfx) = self.gfx.as_mut() else { return };
        let consumed = gfx.egui.on_window_event(&gfx.window, &event).consumed;
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                gfx.surface_config.width = size.width.max(1);
                gfx.surface_config.height = size.height.max(1);
                gfx.surface.configure(gfx.gpu.device(), &gfx.surface_config);
                gfx.window.request_redraw();
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.frame() {
                    self.fail(event_loop, e);
                }
            }
            WindowEvent::ModifiersChanged(m) => self.shift = m.state().shift_key(),
            WindowEvent::KeyboardInput { event, .. }
                if !consumed && event.state == ElementState::Pressed && !event.repeat =>
            {
                self.key(event_loop, &event.logical_key);
            }
            WindowEvent::MouseInput { state, button, .. } => {
                let down = state == ElementState::Pressed && !consumed;
                match button {
                    MouseButton::Left => self.drag_left = down,
                    MouseButton::Right => self.drag_right = down,
                    _ => {}
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                let p = (position.x, position.y);
                if let Some(last) = self.cursor.replace(p) {
                    let (dx, dy) = (p.0 - last.0, p.1 - last.1);
                    if self.drag_left {
                        self.state.orbit(dx, dy);
                        self.moved = true;
                    }
                    if self.drag_right {
                        let k = self.image_per_window_px();
                        let height = self.gfx.as_ref().expect("open").scene.image().height;
                        self.state.pan(dx * k, dy * k, height as f64);
                        self.moved = true;
                    }
                }
                if self.moved {
                    self.gfx.as_ref().expect("open").window.request_redraw();
                }
            }
            WindowEvent::CursorLeft { .. } => self.cursor = None,
            // A finger lifted over the overlay still leaves.
            WindowEvent::Touch(t)
                if !consumed
                    || matches!(
                        t.phase,
                        winit::event::TouchPhase::Ended | winit::event::TouchPhase::Cancelled
                    ) =>
            {
                self.touch(t);
                if self.moved {
                    self.gfx.as_ref().expect("open").window.request_redraw();
                }
            }
            WindowEvent::MouseWheel {
                delta: MouseScrollDelta::LineDelta(..),
                ..
            } if self.wheel_button == Some(ElementState::Released) => {
                // The second half of one notch (see `wheel_button`).
                self.wheel_button = None;
            }
            WindowEvent::MouseWheel { delta, .. } if !consumed => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y as f64,
                    MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
                };
                if self.shift {
                    self.state.zoom_fov(steps);
                } else {
                    self.state.zoom(steps);
                }
                self.moved = true;
                gfx.window.request_redraw();
            }
            _ => {
                if consumed {
                    gfx.window.request_redraw();
                }
            }
        }
    }

    fn device_event(
        &mut self,
        _event_loop: &ActiveEventLoop,
        _id: winit::event::DeviceId,
        event: winit::event::DeviceEvent,
    ) {
        if let winit::event::DeviceEvent::Button {
            button: 4..=7,
            state,
        } = event
        {
            self.wheel_button = Some(state);
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        // Keeps a playing clock's frames coming even without input.
        if self.state.playing
            && let Some(g) = &self.gfx
        {
            g.window.request_redraw();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every text shape of `shapes` with the rectangle it shows in.
    fn texts(shapes: &[egui::epaint::ClippedShape]) -> Vec<(String, egui::Rect, egui::Rect)> {
        fn walk(
            s: &egui::Shape,
            clip: egui::Rect,
            out: &mut Vec<(String, egui::Rect, egui::Rect)>,
        ) {
            match s {
                egui::Shape::Text(t) => {
                    out.push((t.galley.text().to_string(), t.visual_bounding_rect(), clip))
                }
                egui::Shape::Vec(v) => v.iter().for_each(|s| walk(s, clip, out)),
                _ => {}
            }
        }
        let mut out = Vec::new();
        for c in shapes {
            walk(&c.shape, c.clip_rect, &mut out);
        }
        out
    }

    #[test]
    fn the_overlay_and_the_help_fit_small_windows() {
        // The overlay's longest lines, and the help's whole table, at the
        // guide's 320 x 240, smaller, and large.
        let lines: Vec<String> = [
            "12.3 frames/s (GPU 81.25 ms a frame), moving: preview at 160x120",
            "distance 17.000 r_s, elevation 8.0 deg, fov 55.0 deg",
            "model gr, spectral: shift on, Doppler on, beaming off",
            "g on the disk 0.493 to 1.447",
            "t = 1234.5 s (29.1 r_s/c), rotation paused (1.000 s per s)",
            "wrote /tmp/some/where/quick_shot12.png and quick_shot12.exr",
            "h: help",
        ]
        .map(String::from)
        .to_vec();
        for (w, h) in [(320.0, 240.0), (400.0, 200.0), (1280.0, 720.0)] {
            let screen = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(w, h));
            for (overlay, help) in [(true, false), (false, true)] {
                let ctx = egui::Context::default();
                let raw = egui::RawInput {
                    screen_rect: Some(screen),
                    ..Default::default()
                };
                let mut open = help;
                // Windows take a few passes to settle their size.
                let mut out = None;
                for _ in 0..4 {
                    out = Some(ctx.run_pass(raw.clone(), |ctx| {
                        draw_ui(ctx, None, &lines, overlay, &mut open)
                    }));
                }
                let shown = texts(&out.unwrap().shapes);
                for (text, rect, clip) in &shown {
                    let visible = clip.intersect(screen).expand(0.5);
                    assert!(
                        visible.contains_rect(*rect),
                        "{w}x{h}: {text:?} at {rect:?} is cut (visible {visible:?})"
                    );
                }
                let all: String = shown
                    .iter()
                    .map(|t| t.0.replace('\n', " "))
                    .collect::<Vec<_>>()
                    .join(" ");
                let words = |t: &str| t.split_whitespace().map(str::to_string).collect::<Vec<_>>();
                let want: Vec<String> = if overlay {
                    lines.iter().flat_map(|l| words(l)).collect()
                } else {
                    CONTROLS
                        .iter()
                        .flat_map(|(k, d)| words(k).into_iter().chain(words(d)))
                        .collect()
                };
                for word in want {
                    assert!(
                        all.contains(&word),
                        "{w}x{h}: {word:?} not shown in {all:?}"
                    );
                }
            }
        }
    }
}
