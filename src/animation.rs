//! Time: the `[animation]` table as a timeline of frames, the disk's
//! rotation law and the camera's path.
//!
//! Times are coordinate times of the Schwarzschild metric (seconds in the
//! config; r_s/c inside the renderer). Frame k shows
//! t_k = start + k * duration / frames. The disk turns counter-clockwise
//! seen from +z: Keplerian rings by Omega(r) t, Omega = sqrt(GM / r^3)
//! (exact for circular orbits in coordinate time, in both ray models), or
//! rigidly with a period.

use crate::config::{AnimationConfig, KeyframeConfig, OrbitConfig, RotationKind};
use crate::physics::Spacetime;
use glam::{DVec2, DVec3};
use std::path::PathBuf;

/// Most radians the disk may have turned by the time rendered: f64 keeps
/// the angle to 2^32 epsilon, 1e-6 rad, a thousandth of a texel of the
/// shipped disk.
pub const MAX_PHASE: f64 = 4_294_967_296.0;

/// How the disk's material turns.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum DiskRotation {
    /// It does not (still renders).
    #[default]
    None,
    /// Each ring on the circular orbit of this spacetime (sqrt(GM / r^3)
    /// in Schwarzschild's coordinate time; the seed model's Newtonian
    /// orbits turn at the same rate).
    Keplerian(Spacetime),
    /// All of it at this angular velocity (radians per r_s/c).
    Rigid(f64),
}

impl DiskRotation {
    /// The angle (radians) the material at cylindrical radius `r` (r_s)
    /// has turned by at time `tau` (r_s/c).
    #[inline]
    pub fn angle(self, r: f64, tau: f64) -> f64 {
        match self {
            DiskRotation::Keplerian(st) => self.ring_angle(st.ring_radius(r), tau),
            _ => self.ring_angle(r, tau),
        }
    }

    /// The angle (radians) the ring of radius `r` (r_s; Boyer-Lindquist's
    /// with spin) has turned by at time `tau` (r_s/c).
    #[inline]
    fn ring_angle(self, r: f64, tau: f64) -> f64 {
        match self {
            DiskRotation::None => 0.0,
            DiskRotation::Keplerian(st) => st.orbital_angular_velocity(r) * tau,
            DiskRotation::Rigid(omega) => omega * tau,
        }
    }

    /// `p` turned back by the angle its ring has turned: the point of the
    /// material's own (time-zero) frame that lies at `p` at time `tau`.
    #[inline]
    pub fn unturn(self, p: DVec3, tau: f64) -> DVec3 {
        if self == DiskRotation::None || tau == 0.0 {
            return p;
        }
        let a = self.angle((p.x * p.x + p.y * p.y).sqrt(), tau);
        turn_back(p.truncate(), a).extend(p.z)
    }

    /// Whether the disk has turned at time `tau` (else unturn_plane is
    /// the identity).
    pub fn turns(self, tau: f64) -> bool {
        self != DiskRotation::None && tau != 0.0
    }

    /// [`DiskRotation::unturn`] of a point of the disk's plane in its
    /// polar coordinates ([`crate::physics::Spacetime::disk_plane`]),
    /// whose length is its ring's radius. A turn about the axis keeps
    /// Boyer-Lindquist's r and adds to both azimuths alike: turning the
    /// plane's Cartesian point and mapping it is the same.
    #[inline]
    pub fn unturn_plane(self, q: DVec2, tau: f64) -> DVec2 {
        if !self.turns(tau) {
            return q;
        }
        turn_back(q, self.ring_angle((q.x * q.x + q.y * q.y).sqrt(), tau))
    }
}

/// `p` turned clockwise (seen from +z) by `a` radians.
#[inline]
fn turn_back(p: DVec2, a: f64) -> DVec2 {
    let (s, c) = (-a).sin_cos();
    DVec2::new(c * p.x - s * p.y, s * p.x + c * p.y)
}

/// A camera pose (lengths in metres, fov in degrees).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// Centre of projection.
    pub position: DVec3,
    /// Point at the image centre.
    pub look_at: DVec3,
    /// Up direction.
    pub up: DVec3,
    /// Vertical field of view.
    pub fov: f64,
}

impl From<&crate::config::CameraConfig> for Pose {
    /// The pose `[camera]` gives.
    fn from(c: &crate::config::CameraConfig) -> Pose {
        Pose {
            position: DVec3::from_array(c.position),
            look_at: DVec3::from_array(c.look_at),
            up: DVec3::from_array(c.up),
            fov: c.fov,
        }
    }
}

/// Where the camera is over time.
#[derive(Clone, Debug, PartialEq)]
pub enum CameraPath {
    /// Where `[camera]` puts it.
    Fixed,
    /// On a sphere about the hole, azimuth and elevation (radians) moving
    /// linearly from start to end over the animation.
    Orbit {
        /// Azimuth at the start and end.
        azimuth: [f64; 2],
        /// Elevation at the start and end.
        elevation: [f64; 2],
        /// Distance from the hole (m).
        distance: f64,
        /// Point looked at (m).
        look_at: DVec3,
    },
    /// Through keyframes (time in s, pose), cubic Hermite with
    /// Catmull-Rom tangents: C1, through every keyframe.
    Keyframes(Vec<(f64, Pose)>),
}

/// A validated `[animation]` table.
#[derive(Clone, Debug, PartialEq)]
pub struct Timeline {
    /// Whether the table gives frames, fps and duration (an animation);
    /// without them it only sets a still's clock (`start`, the rotation),
    /// with one frame of no duration.
    pub timed: bool,
    /// Number of frames.
    pub frames: u32,
    /// Frames per second of the video.
    pub fps: f64,
    /// Simulated time spanned (s).
    pub duration: f64,
    /// Time of frame 0 (s).
    pub start: f64,
    /// The disk's rotation.
    pub rotation: DiskRotation,
    /// Rays see the disk when their light left it.
    pub light_travel_time: bool,
    /// The video file, if any.
    pub video: Option<PathBuf>,
    /// MP4 quality (x264's crf).
    pub quality: u32,
    /// The camera's path.
    pub camera: CameraPath,
}

/// Most frames an animation may have.
pub const MAX_FRAMES: u32 = 1_000_000;

/// Why an `[animation]` table is invalid: (key, value, what was expected).
pub type AnimationError = (String, String, String);

fn bad(key: &str, value: impl std::fmt::Debug, expected: &str) -> AnimationError {
    (key.to_string(), format!("{value:?}"), expected.to_string())
}

impl Timeline {
    /// Validates `[animation]`; `r_s` (m) converts rigid periods to the
    /// renderer's time unit.
    pub fn new(
        a: &AnimationConfig,
        r_s: f64,
        spacetime: Spacetime,
    ) -> Result<Timeline, AnimationError> {
        let (timed, frames, fps, duration) = timing(a)?;
        let rotation = disk_rotation(a, r_s, spacetime)?;
        if a.keyframes.as_ref().is_some_and(Vec::is_empty) {
            return Err(bad(
                "animation.keyframe",
                Vec::<f64>::new(),
                "expected one or more [[animation.keyframe]] tables (a camera path through them), or no animation.keyframe",
            ));
        }
        let keyframes = a.keyframes.as_deref().unwrap_or_default();
        let camera = match (&a.orbit, keyframes.is_empty()) {
            (Some(_), false) => {
                return Err(bad(
                    "animation.orbit",
                    "[animation.orbit] and [[animation.keyframe]]",
                    "choose one camera path",
                ));
            }
            (Some(o), true) => orbit_path(o, r_s)?,
            (None, false) => keyframe_path(keyframes)?,
            (None, true) => CameraPath::Fixed,
        };
        Ok(Timeline {
            timed,
            frames,
            fps,
            duration,
            start: a.start,
            rotation,
            light_travel_time: a.light_travel_time,
            video: a.video.clone(),
            quality: a.quality,
            camera,
        })
    }

    /// Time of frame `k` (s).
    pub fn time(&self, k: u32) -> f64 {
        self.start + k as f64 * self.duration / self.frames as f64
    }

    /// The camera at time `t` (s), from `base` (the `[camera]` table's pose)
    /// where the path leaves something open.
    pub fn pose(&self, t: f64, base: &Pose) -> Pose {
        match &self.camera {
            CameraPath::Fixed => *base,
            CameraPath::Orbit {
                azimuth,
                elevation,
                distance,
                look_at,
            } => {
                let u = if self.duration > 0.0 {
                    ((t - self.start) / self.duration).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let az = azimuth[0] + (azimuth[1] - azimuth[0]) * u;
                let el = elevation[0] + (elevation[1] - elevation[0]) * u;
                Pose {
                    position: *distance
                        * DVec3::new(az.sin() * el.cos(), -az.cos() * el.cos(), el.sin()),
                    look_at: *look_at,
                    up: DVec3::Z,
                    fov: base.fov,
                }
            }
            CameraPath::Keyframes(keys) => hermite(keys, t, base.fov),
        }
    }
}

/// (timed, frames, fps, duration): an animation's, or a still clock's one
/// frame of no duration; each checked.
fn timing(a: &AnimationConfig) -> Result<(bool, u32, f64, f64), AnimationError> {
    let (timed, frames, fps, duration) = match (a.frames, a.fps, a.duration) {
        (Some(n), Some(f), Some(d)) => (true, n, f, d),
        (None, None, None) => (false, 1, 1.0, 0.0),
        (n, f, d) => {
            let given: Vec<&str> = [n.map(|_| "frames"), f.map(|_| "fps"), d.map(|_| "duration")]
                .into_iter()
                .flatten()
                .collect();
            return Err(bad(
                "animation",
                format!("{} without the rest", given.join(" and ")),
                "give frames, fps and duration together for an animation, or none of them for a still's clock (start)",
            ));
        }
    };
    if !timed {
        let animated = [
            a.video.as_ref().map(|_| "animation.video"),
            a.orbit.as_ref().map(|_| "animation.orbit"),
            a.keyframes.as_ref().map(|_| "animation.keyframe"),
        ];
        if let Some(key) = animated.into_iter().flatten().next() {
            return Err(bad(
                key,
                "given",
                "belongs to an animation: give animation.frames, animation.fps and animation.duration",
            ));
        }
    }
    if !(1..=MAX_FRAMES).contains(&frames) {
        return Err(bad(
            "animation.frames",
            frames,
            &format!("expected 1 to {MAX_FRAMES} frames"),
        ));
    }
    if !(fps.is_finite() && fps > 0.0 && fps <= 1000.0) {
        return Err(bad(
            "animation.fps",
            fps,
            "expected 0 < fps <= 1000 frames per second",
        ));
    }
    if !(duration.is_finite() && duration >= 0.0) {
        return Err(bad(
            "animation.duration",
            duration,
            "expected a finite number of seconds >= 0",
        ));
    }
    if !a.start.is_finite() {
        return Err(bad(
            "animation.start",
            a.start,
            "expected a finite time in seconds",
        ));
    }
    if a.quality > 51 {
        return Err(bad(
            "animation.quality",
            a.quality,
            "expected x264's constant rate factor, 0 (lossless) to 51",
        ));
    }
    if let Some(v) = &a.video {
        let ext = v
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        if !matches!(ext.as_deref(), Some("mp4" | "gif" | "png")) {
            return Err(bad(
                "animation.video",
                v,
                "expected a file name ending in .mp4 (through ffmpeg), .gif or .png (animated PNG)",
            ));
        }
    }
    Ok((timed, frames, fps, duration))
}

/// Validates the disk's rotation (`r_s` in m converts a rigid period).
fn disk_rotation(
    a: &AnimationConfig,
    r_s: f64,
    spacetime: Spacetime,
) -> Result<DiskRotation, AnimationError> {
    Ok(match (a.rotation, a.period) {
        (RotationKind::Keplerian, None) => DiskRotation::Keplerian(spacetime),
        (RotationKind::Keplerian, Some(p)) => {
            return Err(bad(
                "animation.period",
                p,
                "applies to rotation = \"rigid\" only (Keplerian rings each have their own)",
            ));
        }
        (RotationKind::Rigid, Some(p)) if p.is_finite() && p != 0.0 => {
            // Radians per r_s/c: 2 pi / (period c / r_s).
            DiskRotation::Rigid(std::f64::consts::TAU * r_s / (p * crate::units::C))
        }
        (RotationKind::Rigid, p) => {
            return Err(bad(
                "animation.period",
                p,
                "rotation = \"rigid\" needs a non-zero period in seconds (negative turns clockwise)",
            ));
        }
    })
}

/// Validates `[animation.orbit]` (`r_s` in m).
fn orbit_path(o: &OrbitConfig, r_s: f64) -> Result<CameraPath, AnimationError> {
    for (key, v) in [("azimuth", o.azimuth), ("elevation", o.elevation)] {
        if !v.iter().all(|x| x.is_finite()) {
            return Err(bad(
                &format!("animation.orbit.{key}"),
                v,
                "expected two finite angles in degrees",
            ));
        }
    }
    // Past 2^32 rad an angle's sine has lost 1e-6 rad, as the
    // clock's limit (MAX_PHASE) says for the disk's turn.
    let most = MAX_PHASE.to_degrees();
    if !o.azimuth.iter().all(|x| x.abs() <= most) {
        return Err(bad(
            "animation.orbit.azimuth",
            o.azimuth,
            &format!(
                "expected angles within +-{most:.4e} degrees, where their sine is still known to 1e-6 rad"
            ),
        ));
    }
    if !o.elevation.iter().all(|e| e.abs() < 90.0) {
        return Err(bad(
            "animation.orbit.elevation",
            o.elevation,
            "expected elevations strictly between -90 and 90 degrees (up is +z)",
        ));
    }
    if !(o.distance.is_finite() && o.distance > r_s) {
        return Err(bad(
            "animation.orbit.distance",
            o.distance,
            &format!("expected a distance beyond the horizon (r_s = {r_s:.6e} m)"),
        ));
    }
    Ok(CameraPath::Orbit {
        azimuth: o.azimuth.map(f64::to_radians),
        elevation: o.elevation.map(f64::to_radians),
        distance: o.distance,
        look_at: DVec3::from_array(o.look_at),
    })
}

/// Validates `[[animation.keyframe]]`: finite, in increasing time order.
fn keyframe_path(keyframes: &[KeyframeConfig]) -> Result<CameraPath, AnimationError> {
    let mut keys = Vec::new();
    for (i, k) in keyframes.iter().enumerate() {
        let key = |f: &str| format!("animation.keyframe[{i}].{f}");
        let all = [k.position, k.look_at, k.up].concat();
        if !k.time.is_finite() || !all.iter().all(|x| x.is_finite()) {
            return Err(bad(&key("time"), k.time, "expected finite numbers"));
        }
        if let Some((t, _)) = keys.last()
            && !(k.time > *t)
        {
            return Err(bad(
                &key("time"),
                k.time,
                &format!("keyframes must be in increasing time order (the one before is at {t} s)"),
            ));
        }
        if let Some(f) = k.fov
            && !(f > 0.0 && f < 180.0)
        {
            return Err(bad(
                &key("fov"),
                f,
                "expected degrees between 0 and 180 (exclusive)",
            ));
        }
        keys.push((
            k.time,
            Pose {
                position: DVec3::from_array(k.position),
                look_at: DVec3::from_array(k.look_at),
                up: DVec3::from_array(k.up),
                fov: k.fov.unwrap_or(f64::NAN),
            },
        ));
    }
    Ok(CameraPath::Keyframes(keys))
}

/// Catmull-Rom interpolation of keyframes at time `t` (clamped to the
/// first and last): each segment is the cubic Hermite curve with tangents
/// (p[i+1] - p[i-1]) / (t[i+1] - t[i-1]), one-sided at the ends. Keys
/// without a fov (NaN) have `base_fov`.
fn hermite(keys: &[(f64, Pose)], t: f64, base_fov: f64) -> Pose {
    let n = keys.len();
    let fov = |p: &Pose| if p.fov.is_nan() { base_fov } else { p.fov };
    let at = |k: usize| Pose {
        fov: fov(&keys[k].1),
        ..keys[k].1
    };
    if n == 1 || t <= keys[0].0 {
        return at(0);
    }
    if t >= keys[n - 1].0 {
        return at(n - 1);
    }
    let i = keys.partition_point(|(k, _)| *k <= t) - 1;
    let (t0, t1) = (keys[i].0, keys[i + 1].0);
    let h = t1 - t0;
    let s = (t - t0) / h;
    let (h00, h10, h01, h11) = (
        2.0 * s * s * s - 3.0 * s * s + 1.0,
        s * s * s - 2.0 * s * s + s,
        -2.0 * s * s * s + 3.0 * s * s,
        s * s * s - s * s,
    );
    let tangent = |j: usize, f: &dyn Fn(&Pose) -> DVec3| {
        let (a, b) = (j.saturating_sub(1), (j + 1).min(n - 1));
        (f(&keys[b].1) - f(&keys[a].1)) / (keys[b].0 - keys[a].0)
    };
    let curve = |f: &dyn Fn(&Pose) -> DVec3| {
        f(&keys[i].1) * h00
            + tangent(i, f) * (h10 * h)
            + f(&keys[i + 1].1) * h01
            + tangent(i + 1, f) * (h11 * h)
    };
    let fov = curve(&|p: &Pose| DVec3::splat(fov(p))).x;
    Pose {
        position: curve(&|p: &Pose| p.position),
        look_at: curve(&|p: &Pose| p.look_at),
        up: curve(&|p: &Pose| p.up),
        fov,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turning_the_disk_commutes_with_its_polar_coordinates() {
        // A spinning hole's disk turns about the axis: unturning the
        // Kerr-Schild point and reading the disk's coordinates there is
        // unturning those coordinates; without spin, bit for bit.
        for st in [Spacetime::Kerr { a: 0.9 }, Spacetime::Kerr { a: -0.6 }] {
            for rot in [DiskRotation::Keplerian(st), DiskRotation::Rigid(0.3)] {
                for (r, phi, tau) in [(1.5, 0.2, 7.0), (4.0, -2.0, 130.0), (9.0, 3.0, 1e3)] {
                    let p = st.disk_plane_point(r, phi);
                    let a = st.disk_plane(rot.unturn(p, tau));
                    let b = rot.unturn_plane(st.disk_plane(p), tau);
                    assert!(a.distance(b) < 1e-12 * r, "{st:?} {rot:?}: {a} vs {b}");
                }
            }
        }
        let s = Spacetime::Schwarzschild;
        let p = DVec3::new(3.1, -4.7, 0.0);
        for rot in [DiskRotation::Keplerian(s), DiskRotation::Rigid(0.3)] {
            let a = s.disk_plane(rot.unturn(p, 11.0));
            assert_eq!(a, rot.unturn_plane(s.disk_plane(p), 11.0));
        }
    }

    fn pose(x: f64, fov: f64) -> Pose {
        Pose {
            position: DVec3::new(x, -100.0, x * x),
            look_at: DVec3::ZERO,
            up: DVec3::Z,
            fov,
        }
    }

    #[test]
    fn keyframes_are_hit_exactly_and_the_path_is_c1() {
        let keys: Vec<(f64, Pose)> = [(0.0, 1.0), (1.0, 3.0), (3.0, -2.0), (4.0, 5.0)]
            .iter()
            .map(|&(t, x)| (t, pose(x, 40.0 + x)))
            .collect();
        for (t, p) in &keys {
            assert_eq!(hermite(&keys, *t, 40.0), *p);
        }
        // Velocity continuous across each interior keyframe.
        let v = |t: f64| {
            (hermite(&keys, t + 1e-6, 40.0).position - hermite(&keys, t - 1e-6, 40.0).position)
                / 2e-6
        };
        for t in [1.0, 3.0] {
            let (l, r) = (
                (hermite(&keys, t, 40.0).position - hermite(&keys, t - 1e-4, 40.0).position) / 1e-4,
                (hermite(&keys, t + 1e-4, 40.0).position - hermite(&keys, t, 40.0).position) / 1e-4,
            );
            assert!(
                (l - r).length() < 1e-2 * v(t).length().max(1.0),
                "{l} vs {r}"
            );
        }
        // Clamped outside.
        assert_eq!(hermite(&keys, -5.0, 40.0), keys[0].1);
        assert_eq!(hermite(&keys, 9.0, 40.0), keys[3].1);
    }

    #[test]
    fn rotation_angles() {
        // Keplerian: Omega = sqrt(1 / (2 r^3)) per r_s/c.
        let a = DiskRotation::Keplerian(Spacetime::Schwarzschild).angle(8.0, 100.0);
        assert!((a - 100.0 / (2.0f64 * 512.0).sqrt()).abs() < 1e-12);
        // Unturning by the angle maps the turned point back.
        let p = DVec3::new(3.0, 4.0, 0.0);
        let t = 7.0;
        let q = DiskRotation::Keplerian(Spacetime::Schwarzschild).unturn(p, t);
        let back = DiskRotation::Keplerian(Spacetime::Schwarzschild).angle(5.0, t);
        let expect = DVec3::new(
            3.0 * back.cos() + 4.0 * back.sin(),
            -3.0 * back.sin() + 4.0 * back.cos(),
            0.0,
        );
        assert!((q - expect).length() < 1e-12, "{q} vs {expect}");
    }
}
