//! What the viewer's controls change, as plain functions of a state: the
//! camera's pose, the physics toggles and the disk's clock. The window
//! turns input into these calls; the state turns itself into config
//! overrides, so a saved view and a render of it agree with the screen.

use crate::animation::Pose;
use crate::config::{ModelKind, Override, SceneConfig};
use glam::{DQuat, DVec3};

/// Degrees of orbit per pixel dragged.
pub const ORBIT_DEG_PER_PX: f64 = 0.25;
/// Distance factor per wheel step (towards the hole for positive steps).
pub const ZOOM_PER_STEP: f64 = 1.1;
/// Highest elevation an orbit reaches (degrees), short of the pole where
/// the azimuth is undefined.
pub const MAX_ELEVATION: f64 = 89.0;
/// Closest approach (r_s): outside the horizon with room for the near
/// side of the view.
pub const MIN_DISTANCE: f64 = 1.05;
/// Farthest distance (r_s).
pub const MAX_DISTANCE: f64 = 1e7;
/// The spins the spin keys step through: tenths, then the near-extremal
/// 0.99 and 0.998 (Thorne's limit for a hole spun up by its disk).
pub const SPINS: [f64; 23] = [
    -0.998, -0.99, -0.9, -0.8, -0.7, -0.6, -0.5, -0.4, -0.3, -0.2, -0.1, 0.0, 0.1, 0.2, 0.3, 0.4,
    0.5, 0.6, 0.7, 0.8, 0.9, 0.99, 0.998,
];

/// The factor a frequency key scales an observed scene's frequencies by
/// (a third of an octave).
pub const FREQUENCY_STEP: f64 = 1.259_921_049_894_873_2;

/// A physics switch of the viewer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Toggle {
    /// `physics.model`: gr or seed.
    Model,
    /// `spectral.enabled`.
    Spectral,
    /// `spectral.shift`.
    Shift,
    /// `spectral.doppler`.
    Doppler,
    /// `spectral.beaming`.
    Beaming,
}

/// The viewer's state: the camera (metres, as in the config), the
/// physics switches and the clock of the disk's rotation.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewState {
    /// The camera now.
    pub pose: Pose,
    /// The camera the scene file gives (reset returns to it).
    pub home: Pose,
    /// Schwarzschild radius (m).
    pub r_s: f64,
    /// Ray model.
    pub model: ModelKind,
    /// The hole's spin a (`black_hole.spin`).
    pub spin: f64,
    /// Spectral rendering and its switches.
    pub spectral: bool,
    /// Frequency shift.
    pub shift: bool,
    /// Doppler shift of the disk's rotation.
    pub doppler: bool,
    /// Relativistic beaming.
    pub beaming: bool,
    /// Coordinate time (s) of the disk's rotation.
    pub time: f64,
    /// The time of the scene file (`animation.start`, else 0).
    pub start: f64,
    /// Whether the clock runs.
    pub playing: bool,
    /// Simulated seconds per second of wall time.
    pub speed: f64,
    /// An observed scene's frequencies (Hz; `observe.frequency`, the
    /// image shows the first), empty for others.
    pub frequencies: Vec<f64>,
}

impl ViewState {
    /// The state a scene file describes (`r_s` in metres); its clock is
    /// stopped, set to run at one turn of the innermost stable orbit
    /// (3 r_s) in 8 seconds.
    pub fn new(cfg: &SceneConfig, r_s: f64) -> ViewState {
        let pose = Pose::from(&cfg.camera);
        let start = cfg.animation.as_ref().map_or(0.0, |a| a.start);
        let st = crate::physics::Spacetime::default();
        let isco_period =
            std::f64::consts::TAU / st.orbital_angular_velocity(st.isco()) * r_s / crate::units::C;
        ViewState {
            pose,
            home: pose,
            r_s,
            model: cfg.physics.model,
            spin: cfg.black_hole.spin,
            spectral: cfg.spectral.enabled,
            shift: cfg.spectral.shift,
            doppler: cfg.spectral.doppler,
            beaming: cfg.spectral.beaming,
            time: start,
            start,
            playing: false,
            speed: isco_period / 8.0,
            frequencies: cfg
                .observe
                .as_ref()
                .map_or(Vec::new(), |o| o.frequency.list()),
        }
    }

    /// Distance of the camera from the hole (r_s).
    pub fn distance(&self) -> f64 {
        self.pose.position.length() / self.r_s
    }

    /// Elevation of the camera above the disk's plane (degrees).
    pub fn elevation(&self) -> f64 {
        let p = self.pose.position;
        (p.z / p.length()).clamp(-1.0, 1.0).asin().to_degrees()
    }

    /// Azimuth of the camera about +z from the -y axis, counter-clockwise
    /// (degrees), as in `[animation.orbit]`.
    pub fn azimuth(&self) -> f64 {
        let p = self.pose.position;
        p.x.atan2(-p.y).to_degrees()
    }

    /// A drag of (`dx`, `dy`) pixels (right, down) orbits the camera about
    /// the hole: right turns the view to the right (the camera moves
    /// clockwise seen from above), up raises the camera. The whole pose
    /// (position, look_at, up) turns, so the framing is kept; elevation
    /// stops short of the poles.
    pub fn orbit(&mut self, dx: f64, dy: f64) {
        let d_az = (-dx * ORBIT_DEG_PER_PX).to_radians();
        let el = self.elevation();
        let want = (el - dy * ORBIT_DEG_PER_PX).clamp(-MAX_ELEVATION, MAX_ELEVATION);
        let d_el = (want - el.clamp(-MAX_ELEVATION, MAX_ELEVATION)).to_radians();
        let p = self.pose.position;
        // Raising turns about the horizontal axis perpendicular to the
        // camera's direction from the hole.
        let side = DVec3::Z.cross(p);
        let raise = if side.length_squared() > 0.0 {
            DQuat::from_axis_angle(side.normalize(), -d_el)
        } else {
            DQuat::IDENTITY
        };
        let q = DQuat::from_rotation_z(d_az) * raise;
        self.pose.position = q * p;
        self.pose.look_at = q * self.pose.look_at;
        self.pose.up = q * self.pose.up;
    }

    /// `steps` wheel steps: positive moves the camera towards the hole by
    /// ZOOM_PER_STEP each, along the line from the hole (logarithmic in
    /// distance), within MIN_DISTANCE..MAX_DISTANCE r_s.
    pub fn zoom(&mut self, steps: f64) {
        let r = self.distance();
        let want = (r * ZOOM_PER_STEP.powf(-steps)).clamp(MIN_DISTANCE, MAX_DISTANCE);
        self.pose.position *= want / r;
    }

    /// Two fingers whose spread grew by `ratio`: the distance divided by
    /// it (as [`ViewState::zoom`] by that many steps), within its limits.
    pub fn pinch(&mut self, ratio: f64) {
        self.zoom(ratio.ln() / ZOOM_PER_STEP.ln());
    }

    /// `steps` wheel steps with shift: positive narrows the field of view
    /// by ZOOM_PER_STEP each, within 1 to 170 degrees.
    pub fn zoom_fov(&mut self, steps: f64) {
        self.pose.fov = (self.pose.fov * ZOOM_PER_STEP.powf(-steps)).clamp(1.0, 170.0);
    }

    /// A right drag of (`dx`, `dy`) pixels on an image `height` pixels
    /// tall moves `look_at` across the view, so the point under the
    /// pointer at look_at's distance follows the pointer.
    pub fn pan(&mut self, dx: f64, dy: f64, height: f64) {
        let p = &mut self.pose;
        let to = p.look_at - p.position;
        let d = to.length();
        let forward = to / d;
        let right = forward.cross(p.up).normalize();
        let up = right.cross(forward);
        let per_px = 2.0 * d * (p.fov.to_radians() / 2.0).tan() / height;
        p.look_at += (-dx * right + dy * up) * per_px;
    }

    /// Flips a switch.
    pub fn toggle(&mut self, t: Toggle) {
        match t {
            Toggle::Model => {
                self.model = match self.model {
                    ModelKind::Gr => ModelKind::Seed,
                    ModelKind::Seed => ModelKind::Gr,
                }
            }
            Toggle::Spectral => self.spectral = !self.spectral,
            Toggle::Shift => self.shift = !self.shift,
            Toggle::Doppler => self.doppler = !self.doppler,
            Toggle::Beaming => self.beaming = !self.beaming,
        }
    }

    /// The next spin of [`SPINS`] above (`up`) or below the current one
    /// (a spin between them from the scene file goes to its neighbour);
    /// at the ends it stays.
    pub fn change_spin(&mut self, up: bool) {
        let a = self.spin;
        let next = if up {
            SPINS.iter().copied().find(|&s| s > a + 1e-12)
        } else {
            SPINS.iter().rev().copied().find(|&s| s < a - 1e-12)
        };
        if let Some(n) = next {
            self.spin = n;
        }
    }

    /// Scales an observed scene's frequencies up (`up`) or down by
    /// [`FREQUENCY_STEP`]; nothing for other scenes.
    pub fn change_frequency(&mut self, up: bool) {
        let k = if up {
            FREQUENCY_STEP
        } else {
            1.0 / FREQUENCY_STEP
        };
        for f in &mut self.frequencies {
            *f *= k;
        }
    }

    /// Runs the clock for `wall` seconds if it is playing.
    pub fn advance(&mut self, wall: f64) {
        if self.playing {
            self.time += wall * self.speed;
        }
    }

    /// Doubles (`faster`) or halves the clock's speed.
    pub fn change_speed(&mut self, faster: bool) {
        self.speed *= if faster { 2.0 } else { 0.5 };
    }

    /// Back to the scene file's camera and time.
    pub fn reset(&mut self) {
        self.pose = self.home;
        self.time = self.start;
    }

    /// The switches that differ from `from`'s as config overrides (they
    /// need a new scene).
    pub fn changed_physics(&self, from: &ViewState) -> Vec<Override> {
        let mut o = Vec::new();
        if self.model != from.model {
            o.push(Override::value("physics.model", self.model.name().into()));
        }
        if self.spin != from.spin {
            o.push(Override::value("black_hole.spin", self.spin.into()));
        }
        for (key, now, then) in [
            ("spectral.enabled", self.spectral, from.spectral),
            ("spectral.shift", self.shift, from.shift),
            ("spectral.doppler", self.doppler, from.doppler),
            ("spectral.beaming", self.beaming, from.beaming),
        ] {
            if now != then {
                o.push(Override::value(key, now.into()));
            }
        }
        if self.frequencies != from.frequencies {
            let list = self.frequencies.iter().map(|&f| toml::Value::Float(f));
            o.push(Override::value(
                "observe.frequency",
                toml::Value::Array(list.collect()),
            ));
        }
        o
    }

    /// The camera as config overrides.
    pub fn camera_overrides(&self) -> Vec<Override> {
        let v3 = |v: DVec3| toml::Value::Array(v.to_array().map(toml::Value::Float).to_vec());
        vec![
            Override::value("camera.position", v3(self.pose.position)),
            Override::value("camera.look_at", v3(self.pose.look_at)),
            Override::value("camera.up", v3(self.pose.up)),
            Override::value("camera.fov", self.pose.fov.into()),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state() -> ViewState {
        let cfg: SceneConfig = toml::from_str(
            r#"
            [image]
            width = 64
            height = 48
            png = "x.png"
            [camera]
            position = [0.0, -2.0e11, 0.0]
            look_at = [0.0, 0.0, 0.0]
            fov = 40.0
            [black_hole]
            mass = 8.57e36
            [sky]
            color = [1.0, 1.0, 1.0]
            "#,
        )
        .unwrap();
        ViewState::new(&cfg, 1.27e10)
    }

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() <= 1e-9 * b.length().max(1.0)
    }

    #[test]
    fn orbit_turns_about_the_hole_keeping_distance_and_framing() {
        let mut s = state();
        let r = s.distance();
        // 360 px right: 90 degrees clockwise seen from above, -y to -x.
        s.orbit(360.0, 0.0);
        assert!((s.azimuth() + 90.0).abs() < 1e-9, "{}", s.azimuth());
        assert!(close(s.pose.position, DVec3::new(-2.0e11, 0.0, 0.0)));
        assert!((s.distance() - r).abs() < 1e-9 * r);
        // Drag up 120 px: 30 degrees up; the view still points at the hole.
        s.orbit(0.0, -120.0);
        assert!((s.elevation() - 30.0).abs() < 1e-9);
        assert!(close(s.pose.look_at, DVec3::ZERO));
        let fwd = (s.pose.look_at - s.pose.position).normalize();
        assert!(s.pose.up.dot(fwd).abs() < 0.6, "up stays clear of the view");
        // Elevation stops short of the pole, whatever the drag.
        s.orbit(0.0, -10_000.0);
        assert!((s.elevation() - MAX_ELEVATION).abs() < 1e-9);
        s.orbit(0.0, 10_000.0);
        assert!((s.elevation() + MAX_ELEVATION).abs() < 1e-9);
        // An orbit and its reverse return the pose.
        let mut t = state();
        t.orbit(37.0, -55.0);
        t.orbit(0.0, 55.0);
        t.orbit(-37.0, 0.0);
        assert!(close(t.pose.position, state().pose.position));
        assert!(close(t.pose.up, DVec3::Z));
    }

    #[test]
    fn zoom_is_logarithmic_and_stays_outside_the_horizon() {
        let mut s = state();
        let r = s.distance();
        s.zoom(2.0);
        assert!((s.distance() - r / 1.21).abs() < 1e-9 * r);
        s.zoom(-2.0);
        assert!((s.distance() - r).abs() < 1e-9 * r);
        s.zoom(1000.0);
        assert!((s.distance() - MIN_DISTANCE).abs() < 1e-12);
        s.zoom(-1e6);
        assert!((s.distance() - MAX_DISTANCE).abs() < 1e-3);
        let mut f = state();
        f.zoom_fov(1.0);
        assert!((f.pose.fov - 40.0 / 1.1).abs() < 1e-12);
        f.zoom_fov(-100.0);
        assert_eq!(f.pose.fov, 170.0);
    }

    #[test]
    fn pan_moves_look_at_by_the_pointer_at_its_distance() {
        let mut s = state();
        // 48 px image, fov 40: half the height spans d tan(20 deg).
        s.pan(-24.0, 0.0, 48.0);
        let d = 2.0e11;
        let want = d * 20f64.to_radians().tan();
        // Dragging left moves the view's centre right: +x seen from -y.
        assert!(
            close(s.pose.look_at, DVec3::new(want, 0.0, 0.0)),
            "{}",
            s.pose.look_at
        );
        // Up a half height, at look_at's new distance d / cos(20 deg).
        s.pan(0.0, -24.0, 48.0);
        let down = want / 20f64.to_radians().cos();
        assert!(
            (s.pose.look_at.z + down).abs() < 1e-9 * down,
            "{}",
            s.pose.look_at
        );
    }

    #[test]
    fn a_pinch_divides_the_distance_by_the_spread_ratio() {
        let mut s = state();
        s.pinch(2.0);
        assert!((s.distance() - 2.0e11 / 2.0 / s.r_s).abs() < 1e-9 * s.distance());
        // Spreads that return to where they began leave it as it was.
        s.pinch(0.8);
        s.pinch(1.25);
        s.pinch(0.5);
        assert!((s.distance() - 2.0e11 / s.r_s).abs() < 1e-9 * s.distance());
        // Its limits hold.
        s.pinch(1e12);
        assert!((s.distance() - MIN_DISTANCE).abs() < 1e-12 * MIN_DISTANCE);
    }

    #[test]
    fn spin_steps_through_the_ladder_and_becomes_an_override() {
        let mut s = state();
        s.change_spin(false);
        assert_eq!(s.spin, -0.1);
        for _ in 0..30 {
            s.change_spin(true);
        }
        assert_eq!(s.spin, 0.998, "stays at the top");
        s.change_spin(false);
        s.change_spin(false);
        assert_eq!(s.spin, 0.9);
        // A file's spin between steps goes to its neighbours.
        s.spin = 0.95;
        s.change_spin(true);
        assert_eq!(s.spin, 0.99);
        s.spin = 0.95;
        s.change_spin(false);
        assert_eq!(s.spin, 0.9);
        for _ in 0..30 {
            s.change_spin(false);
        }
        assert_eq!(s.spin, -0.998, "stays at the bottom");
        let o: Vec<String> = s
            .changed_physics(&state())
            .iter()
            .map(|o| format!("{}={}", o.key, o.value.as_ref().unwrap()))
            .collect();
        assert_eq!(o, ["black_hole.spin=-0.998"]);
        // Every step is a spin the scene accepts.
        assert!(SPINS.windows(2).all(|w| w[0] < w[1]));
        assert!(SPINS.iter().all(|a| a.abs() <= 0.9999));
    }

    #[test]
    fn frequency_keys_scale_an_observed_scenes_frequencies() {
        let text = std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/sgra.toml"),
        )
        .unwrap();
        let cfg: SceneConfig = toml::from_str(&text).unwrap();
        let built = ViewState::new(&cfg, 1.0);
        assert_eq!(built.frequencies, vec![230e9]);
        let mut s = built.clone();
        for _ in 0..3 {
            s.change_frequency(true);
        }
        // Three thirds of an octave: twice the frequency.
        assert!((s.frequencies[0] / 460e9 - 1.0).abs() < 1e-12);
        let o = s.changed_physics(&built);
        assert_eq!(o.len(), 1);
        s.change_frequency(false);
        assert!((s.frequencies[0] / 365.1e9 - 1.0).abs() < 1e-3);
        // A scene without a medium has nothing to scale.
        let mut plain = state();
        plain.change_frequency(true);
        assert!(plain.frequencies.is_empty() && plain.changed_physics(&state()).is_empty());
    }

    #[test]
    fn toggles_clock_and_reset() {
        let mut s = state();
        s.toggle(Toggle::Model);
        s.toggle(Toggle::Spectral);
        s.toggle(Toggle::Beaming);
        assert_eq!(s.model, ModelKind::Seed);
        assert!(s.spectral && s.beaming && s.shift && s.doppler);
        let o: Vec<String> = s
            .changed_physics(&state())
            .iter()
            .map(|o| format!("{}={}", o.key, o.value.as_ref().unwrap()))
            .collect();
        assert_eq!(
            o,
            [
                "physics.model=\"seed\"",
                "spectral.enabled=true",
                "spectral.beaming=true"
            ]
        );
        // The clock runs only when playing; speed doubles and halves.
        s.advance(1.0);
        assert_eq!(s.time, 0.0);
        s.playing = true;
        let v = s.speed;
        s.advance(2.0);
        assert!((s.time - 2.0 * v).abs() < 1e-9 * v);
        s.change_speed(true);
        assert_eq!(s.speed, 2.0 * v);
        s.orbit(100.0, 40.0);
        s.zoom(3.0);
        s.reset();
        assert_eq!(s.pose, state().pose);
        assert_eq!(s.time, 0.0);
        // Camera overrides read back as the same numbers.
        let cam = s.camera_overrides();
        assert_eq!(cam[0].key, "camera.position");
        let back: Vec<f64> = cam[0]
            .value
            .as_ref()
            .unwrap()
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_float().unwrap())
            .collect();
        assert_eq!(back, vec![0.0, -2.0e11, 0.0]);
    }
}
