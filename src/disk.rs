//! The flat accretion disk in the XY plane.
//!
//! The texture spans the square [-R, R]^2 of the disk plane: texture
//! coordinate u runs along +x from x = -R, v along -y from y = +R, so the
//! image looks as the disk does from above (+z) with +x to the right and +y
//! up. Only points with inner <= |p| <= R belong to the disk.

use crate::config::{AlphaMode, Filter};
use crate::texture::Texture;
use glam::{DVec3, Vec4};

/// A textured flat disk (radii in r_s).
#[derive(Clone, Debug)]
pub struct Disk {
    /// Inner radius.
    pub inner: f64,
    /// Outer radius; also half the texture square's side.
    pub outer: f64,
    /// RGBA texture.
    pub texture: Texture,
    /// Texture filter.
    pub filter: Filter,
    /// Alpha use.
    pub alpha: AlphaMode,
    /// Linear colour multiplier.
    pub intensity: f32,
}

impl Disk {
    /// Radii (r_s) between which the disk can stop or colour a ray: the
    /// configured annulus narrowed to where the texture has any alpha,
    /// widened by a texel's diagonal (two for bilinear filtering). The tracer
    /// uses the inner one to capture rays inside the photon sphere early.
    pub fn material_radii(&self) -> (f64, f64) {
        let (w, h) = (self.texture.width, self.texture.height);
        let texel = 2.0 * self.outer / w.min(h) as f64;
        let pad = texel
            * std::f64::consts::SQRT_2
            * if self.filter == Filter::Bilinear {
                2.0
            } else {
                1.0
            };
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for y in 0..h {
            for x in 0..w {
                if self.texture.texel(x, y).w > 0.0 {
                    let px = ((x as f64 + 0.5) / w as f64 * 2.0 - 1.0) * self.outer;
                    let py = (1.0 - (y as f64 + 0.5) / h as f64 * 2.0) * self.outer;
                    let r = px.hypot(py);
                    lo = lo.min(r);
                    hi = hi.max(r);
                }
            }
        }
        if hi == 0.0 {
            // Fully transparent: nothing to hit anywhere.
            return (self.outer, self.outer);
        }
        ((lo - pad).max(self.inner), (hi + pad).min(self.outer))
    }

    /// Premultiplied linear RGBA (intensity applied) at a point of the
    /// plane, or `None` where the disk has no material (outside its annulus
    /// or alpha 0).
    #[inline]
    pub fn sample(&self, p: DVec3) -> Option<Vec4> {
        let r2 = p.x * p.x + p.y * p.y;
        if r2 > self.outer * self.outer || r2 < self.inner * self.inner {
            return None;
        }
        let u = (p.x + self.outer) / (2.0 * self.outer);
        let v = (self.outer - p.y) / (2.0 * self.outer);
        let t = self.texture.sample(u, v, self.filter, false);
        if t.w <= 0.0 {
            return None;
        }
        let k = self.intensity;
        Some(Vec4::new(t.x * k, t.y * k, t.z * k, t.w))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn disk() -> Disk {
        // 2x2 texture: top-left red, top-right green, bottom-left blue,
        // bottom-right transparent.
        let img = image::RgbaImage::from_fn(2, 2, |x, y| match (x, y) {
            (0, 0) => image::Rgba([255, 0, 0, 255]),
            (1, 0) => image::Rgba([0, 255, 0, 255]),
            (0, 1) => image::Rgba([0, 0, 255, 255]),
            _ => image::Rgba([255, 255, 255, 0]),
        });
        Disk {
            inner: 1.0,
            outer: 10.0,
            texture: Texture::from_image(image::DynamicImage::ImageRgba8(img)),
            filter: Filter::Nearest,
            alpha: AlphaMode::Cutout,
            intensity: 1.0,
        }
    }

    #[test]
    fn quadrants_follow_the_documented_orientation() {
        let d = disk();
        assert_eq!(d.sample(DVec3::new(-5.0, 5.0, 0.0)).unwrap().x, 1.0); // +y, -x: top-left
        assert_eq!(d.sample(DVec3::new(5.0, 5.0, 0.0)).unwrap().y, 1.0);
        assert_eq!(d.sample(DVec3::new(-5.0, -5.0, 0.0)).unwrap().z, 1.0);
        assert!(d.sample(DVec3::new(5.0, -5.0, 0.0)).is_none(), "alpha 0");
    }

    #[test]
    fn material_radii_follow_the_alpha() {
        // Opaque only in a ring 4..6 r_s of a 10 r_s disk.
        let n = 200;
        let img = image::RgbaImage::from_fn(n, n, |x, y| {
            let px = ((x as f64 + 0.5) / n as f64 * 2.0 - 1.0) * 10.0;
            let py = (1.0 - (y as f64 + 0.5) / n as f64 * 2.0) * 10.0;
            let r = px.hypot(py);
            image::Rgba([255, 255, 255, if (4.0..6.0).contains(&r) { 255 } else { 0 }])
        });
        let mut d = disk();
        d.texture = Texture::from_image(image::DynamicImage::ImageRgba8(img));
        let (lo, hi) = d.material_radii();
        let texel = 20.0 / n as f64;
        assert!(lo <= 4.0 && lo > 4.0 - 3.0 * texel, "{lo}");
        assert!(hi >= 6.0 && hi < 6.0 + 3.0 * texel, "{hi}");
        d.inner = 5.0;
        assert_eq!(d.material_radii().0, 5.0);
    }

    #[test]
    fn annulus_bounds() {
        let d = disk();
        assert!(
            d.sample(DVec3::new(-0.5, 0.5, 0.0)).is_none(),
            "inside inner radius"
        );
        assert!(
            d.sample(DVec3::new(-9.0, 9.0, 0.0)).is_none(),
            "in the square, outside the circle"
        );
        assert!(d.sample(DVec3::new(-7.0, 7.0, 0.0)).is_some());
    }
}
