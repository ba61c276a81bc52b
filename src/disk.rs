//! The flat accretion disk in the XY plane.
//!
//! The texture spans the square [-R, R]^2 of the disk plane: texture
//! coordinate u runs along +x from x = -R, v along -y from y = +R, so the
//! image looks as the disk does from above (+z) with +x to the right and +y
//! up. Only points with inner <= |p| <= R belong to the disk. The disk turns
//! counter-clockwise seen from +z (for its Doppler shift). The plane's
//! points are in the disk's polar coordinates, (r cos phi, r sin phi)
//! ([`crate::physics::Spacetime::disk_plane`]): around a spinning hole
//! Boyer-Lindquist's r and phi, so a ring of the texture is a ring of the
//! disk's orbits and a spoke a line of constant phi.

use crate::config::{AlphaMode, Filter};
use crate::spectral::SpectralContext;
use crate::spectral_texture::SpectralTexture;
use crate::spectrum::uplift::uplift;
use crate::texture::{Footprint, Texture};
use crate::thin_disk::ThinDisk;
use glam::{DVec2, Vec3};
use std::ops::Range;

/// What the disk is made of.
#[derive(Clone, Debug)]
pub enum DiskMaterial {
    /// An RGBA texture (uplifted to spectra in spectral mode).
    Rgb(Texture),
    /// A spectral texture set with its own alpha.
    Spectral(SpectralTexture),
}

/// A textured flat disk (radii in r_s).
#[derive(Clone, Debug)]
pub struct Disk {
    /// Inner radius.
    pub inner: f64,
    /// Outer radius; also half the texture square's side.
    pub outer: f64,
    /// Texture.
    pub material: DiskMaterial,
    /// Texture filter.
    pub filter: Filter,
    /// Alpha use.
    pub alpha: AlphaMode,
    /// Linear multiplier of the emission.
    pub intensity: f32,
    /// A thin disk's blackbody light, which the texture's luminance then
    /// modulates (`disk.emission = "thin"`).
    pub thin: Option<ThinDisk>,
    /// The spacetime whose polar coordinates the disk's plane is read in
    /// ([`crate::physics::Spacetime::disk_plane`]).
    pub spacetime: crate::physics::Spacetime,
    /// The radius (r_s) inside which the texture holds no material
    /// ([`Disk::material_radii`]).
    pub material_inner: f64,
}

/// Where a ray met the disk's material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiskHit {
    /// Texture coordinates.
    pub u: f64,
    /// Texture coordinates (down).
    pub v: f64,
    /// Coverage in (0, 1].
    pub alpha: f32,
    /// The ring's radius (r_s): the distance from the axis, or with spin
    /// Boyer-Lindquist's r.
    pub r: f64,
    /// The sample's footprint in texture coordinates: the derivatives of
    /// (u, v) per pixel along x and y, where the render keeps footprints.
    pub duv: Option<[DVec2; 2]>,
}

impl Disk {
    /// The material at the point `q` of the plane in the disk's polar
    /// coordinates, (r cos phi, r sin phi) (see the module's notes), or
    /// `None` where the disk has none (outside its annulus or alpha 0).
    #[inline]
    pub fn hit(&self, q: DVec2) -> Option<DiskHit> {
        self.hit_footprint(q, None)
    }

    /// [`Disk::hit`] of a sample whose footprint on the plane has
    /// derivatives `dq` per pixel along x and y (the texture's filter
    /// reads over it).
    #[inline]
    pub fn hit_footprint(&self, q: DVec2, dq: Option<[DVec2; 2]>) -> Option<DiskHit> {
        let r2 = q.x * q.x + q.y * q.y;
        if !(r2 <= self.outer * self.outer && r2 >= self.inner * self.inner) {
            return None;
        }
        let r = r2.sqrt();
        let side = 2.0 * self.outer;
        let u = (q.x + self.outer) / side;
        let v = (self.outer - q.y) / side;
        let point = DiskHit {
            u,
            v,
            alpha: 0.0,
            r,
            duv: None,
        };
        let with_alpha = |h: DiskHit| {
            let alpha = self.alpha_at(&h);
            (alpha > 0.0).then_some(DiskHit { alpha, ..h })
        };
        // (Only the footprint filter reads a footprint.)
        let Some(dq) = dq.filter(|_| self.filter == Filter::Footprint) else {
            return with_alpha(point);
        };
        let dq = self.short_of_the_hole(q, r, dq);
        let over = DiskHit {
            duv: Some(dq.map(|d| DVec2::new(d.x, -d.y) / side)),
            ..point
        };
        if self.alpha == AlphaMode::Blend {
            return with_alpha(over);
        }
        // Whether a cutout stops the ray is a question of the point: the
        // footprint's alpha is non-zero wherever its filter touches
        // material, and stopping there would close every gap narrower
        // than the filter and widen the material by it, in the material's
        // full colour (the filtered premultiplied colour over the filtered
        // alpha). The edge between material and gap is one between what
        // samples meet, which they resolve; the footprint filters the
        // colour they see. A point without material is passed before any
        // filtering; where the filter's alpha rounds to nothing (a level's
        // edge) the point's own lookup stands.
        let here = with_alpha(point)?;
        Some(with_alpha(over).unwrap_or(here))
    }

    /// The material's alpha at a hit, through the disk's filter.
    #[inline]
    fn alpha_at(&self, hit: &DiskHit) -> f32 {
        match &self.material {
            DiskMaterial::Rgb(t) => self.rgba(t, hit).w,
            DiskMaterial::Spectral(s) => self.with_texels(s, hit, |texels| s.coverage(texels)),
        }
    }

    /// The footprint `dq` (r_s per pixel) of a hit at `q`, ring radius
    /// `r`, shrunk where it reaches across the material's inner edge to
    /// stop there. The hole is an edge between what the samples meet:
    /// they resolve it (adaptive sampling refines it as any change of
    /// class). A filter reading across it would light hits in the hole
    /// with the material's light, and with blended alpha dim the material
    /// at the edge with the hole's transparency, each sample then showing
    /// what lies behind its own ray instead of what the pixel's other part
    /// sees. It also keeps every hit within the material's radii, the
    /// tracer's limits.
    fn short_of_the_hole(&self, q: DVec2, r: f64, dq: [DVec2; 2]) -> [DVec2; 2] {
        if r <= 0.0 {
            return dq;
        }
        let n = q / r;
        // The filter's ellipse reaches this far along the radius.
        let reach = n.dot(dq[0]).hypot(n.dot(dq[1]));
        let room = (r - self.material_inner).max(0.0);
        if reach > room {
            let k = room / reach;
            [dq[0] * k, dq[1] * k]
        } else {
            dq
        }
    }

    /// Whether the disk's material varies across it, so that a filter has
    /// something to read: a thin disk without a texture has a uniform
    /// one texel, the same over any footprint.
    pub fn textured(&self) -> bool {
        match &self.material {
            DiskMaterial::Rgb(t) => t.width * t.height > 1,
            DiskMaterial::Spectral(_) => true,
        }
    }

    /// The sample's footprint in texture units, where it has one.
    #[inline]
    fn footprint(h: &DiskHit) -> Option<Footprint> {
        h.duv.map(|[dx, dy]| Footprint { dx, dy })
    }

    /// The RGBA texture at a hit, through the disk's filter.
    #[inline]
    fn rgba(&self, t: &Texture, h: &DiskHit) -> glam::Vec4 {
        t.sample_filtered(h.u, h.v, self.filter, Self::footprint(h).as_ref(), false)
    }

    /// `f` of the spectral texture's texels and weights at a hit (a
    /// footprint reads any number of them: a list kept per thread).
    #[inline]
    fn with_texels<R>(
        &self,
        s: &SpectralTexture,
        h: &DiskHit,
        f: impl FnOnce(&[(usize, f32)]) -> R,
    ) -> R {
        thread_local! {
            static TEXELS: std::cell::RefCell<Vec<(usize, f32)>> =
                const { std::cell::RefCell::new(Vec::new()) };
        }
        TEXELS.with_borrow_mut(|texels| {
            s.texels_into(h.u, h.v, self.filter, Self::footprint(h).as_ref(), texels);
            f(texels)
        })
    }

    /// Premultiplied linear RGB at a hit (intensity applied). RGB renders
    /// convert a spectral material to RGB when the scene is built; a
    /// spectral one left here reads as black.
    #[inline]
    pub fn rgb(&self, h: &DiskHit) -> Vec3 {
        if self.thin.is_some() {
            return self.thin_rgb(h) * self.intensity;
        }
        match &self.material {
            DiskMaterial::Rgb(t) => self.rgba(t, h).truncate() * self.intensity,
            DiskMaterial::Spectral(_) => {
                debug_assert!(false, "spectral disks are converted for RGB renders");
                Vec3::ZERO
            }
        }
    }

    /// Adds `k` times the premultiplied emission seen at the camera
    /// wavelengths in `range`, for light arriving with frequency ratio `g`.
    pub fn add_spectrum(
        &self,
        h: &DiskHit,
        g: f64,
        ctx: &SpectralContext,
        k: f32,
        range: Range<usize>,
        out: &mut [f32],
    ) {
        let k = k * self.intensity * ctx.radiance_factor(g);
        if let Some(thin) = &self.thin {
            // With beaming, g^5 B_lambda(g lambda; T) = B_lambda(lambda; g T).
            let k = k * self.modulation(h);
            let kelvin = thin.temperature(h.r);
            for i in range {
                out[i] += k * thin.radiance_at(g * ctx.wavelengths.nm[i], kelvin) as f32;
            }
            return;
        }
        match &self.material {
            DiskMaterial::Rgb(t) => {
                let px = self.rgba(t, h);
                let spec = uplift(px.truncate() / px.w);
                let k = k * px.w;
                for i in range {
                    out[i] += k * spec.emission(g * ctx.wavelengths.nm[i]) as f32;
                }
            }
            DiskMaterial::Spectral(s) => self.with_texels(s, h, |texels| {
                s.add_premultiplied(texels, k, g, ctx, range, out)
            }),
        }
    }

    /// A thin disk's texture as a pattern: its linear luminance
    /// (premultiplied by alpha, like the colour it stands for).
    #[inline]
    fn modulation(&self, h: &DiskHit) -> f32 {
        match &self.material {
            DiskMaterial::Rgb(t) => crate::spectrum::color::luminance(self.rgba(t, h).truncate()),
            DiskMaterial::Spectral(_) => 1.0,
        }
    }

    /// A thin disk's light at a hit (linear sRGB, its pattern applied,
    /// before `intensity`).
    #[inline]
    fn thin_rgb(&self, h: &DiskHit) -> Vec3 {
        let thin = self.thin.as_ref().expect("a thin disk");
        crate::spectrum::color::xyz_to_linear_srgb(thin.xyz(h.r).as_dvec3()).as_vec3()
            * self.modulation(h)
    }

    /// A `size`-square texture of what the thin disk emits (RGB, its
    /// pattern applied, before `intensity`, like a texture) at the texel
    /// centres, for its glow on lit surfaces.
    pub fn thin_texture(&self, size: u32) -> Texture {
        let mut texels = Vec::with_capacity((size * size) as usize);
        for y in 0..size {
            for x in 0..size {
                let (px, py) = self.texel_centre(x, y, size, size);
                texels.push(match self.hit(DVec2::new(px, py)) {
                    Some(h) => self.thin_rgb(&h).extend(h.alpha).to_array(),
                    None => [0.0; 4],
                });
            }
        }
        Texture::linear(size, size, texels)
    }

    /// Centre (x, y) in the disk plane (its polar coordinates) of texel
    /// (x, y) of a w x h texture spanning [-outer, outer]^2, row 0 at +y.
    #[inline]
    pub fn texel_centre(&self, x: u32, y: u32, w: u32, h: u32) -> (f64, f64) {
        (
            ((x as f64 + 0.5) / w as f64 * 2.0 - 1.0) * self.outer,
            (1.0 - (y as f64 + 0.5) / h as f64 * 2.0) * self.outer,
        )
    }

    /// Radii (r_s) between which the disk can stop or colour a ray: the
    /// configured annulus narrowed to where the texture has any alpha,
    /// widened by a texel's diagonal (two for bilinear filtering). The tracer
    /// uses the inner one to capture rays inside the photon sphere early.
    pub fn material_radii(&self) -> (f64, f64) {
        let (w, h) = match &self.material {
            DiskMaterial::Rgb(t) => (t.width, t.height),
            DiskMaterial::Spectral(s) => (s.width, s.height),
        };
        let texel = 2.0 * self.outer / w.min(h) as f64;
        let pad = texel
            * std::f64::consts::SQRT_2
            // (A footprint stops at the inner edge: Disk::hit_footprint.)
            * if self.filter != Filter::Nearest {
                2.0
            } else {
                1.0
            };
        let (mut lo, mut hi, mut any) = (f64::INFINITY, 0.0f64, false);
        for y in 0..h {
            for x in 0..w {
                let a = match &self.material {
                    DiskMaterial::Rgb(t) => t.texel(x, y).w,
                    DiskMaterial::Spectral(s) => s.alpha((y * w + x) as usize),
                };
                if a > 0.0 {
                    any = true;
                    let (px, py) = self.texel_centre(x, y, w, h);
                    let r = px.hypot(py);
                    lo = lo.min(r);
                    hi = hi.max(r);
                }
            }
        }
        if !any {
            // Fully transparent: nothing to hit anywhere.
            return (self.outer, self.outer);
        }
        ((lo - pad).max(self.inner), (hi + pad).min(self.outer))
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
            material: DiskMaterial::Rgb(Texture::from_image(image::DynamicImage::ImageRgba8(img))),
            filter: Filter::Nearest,
            alpha: AlphaMode::Cutout,
            intensity: 1.0,
            thin: None,
            spacetime: crate::physics::Spacetime::Schwarzschild,
            material_inner: 1.0,
        }
    }

    fn rgb_at(d: &Disk, x: f64, y: f64) -> Option<Vec3> {
        d.hit(DVec2::new(x, y)).map(|h| d.rgb(&h))
    }

    #[test]
    fn quadrants_follow_the_documented_orientation() {
        let d = disk();
        assert_eq!(rgb_at(&d, -5.0, 5.0).unwrap().x, 1.0); // +y, -x: top-left
        assert_eq!(rgb_at(&d, 5.0, 5.0).unwrap().y, 1.0);
        assert_eq!(rgb_at(&d, -5.0, -5.0).unwrap().z, 1.0);
        assert!(rgb_at(&d, 5.0, -5.0).is_none(), "alpha 0");
    }

    /// A 10 r_s disk opaque white but for a transparent ring of radii
    /// 6..7 r_s, read over footprints with alpha mode `alpha`.
    fn gapped(alpha: AlphaMode) -> Disk {
        let n = 200;
        let img = image::RgbaImage::from_fn(n, n, |x, y| {
            let px = ((x as f64 + 0.5) / n as f64 * 2.0 - 1.0) * 10.0;
            let py = (1.0 - (y as f64 + 0.5) / n as f64 * 2.0) * 10.0;
            let a = if (6.0..7.0).contains(&px.hypot(py)) {
                0
            } else {
                255
            };
            image::Rgba([255, 255, 255, a])
        });
        let mut d = disk();
        d.material = DiskMaterial::Rgb(Texture::from_image(image::DynamicImage::ImageRgba8(img)));
        d.filter = Filter::Footprint;
        d.alpha = alpha;
        d
    }

    #[test]
    fn a_cutout_stops_rays_where_the_point_has_material() {
        // A footprint 1.2 r_s a pixel along the radius (its filter
        // reaching 0.94 r_s), centred in the gap 0.5 r_s from its edges:
        // the filter reaches the material on both sides, the point holds
        // none.
        let q = DVec2::new(0.0, 6.5);
        let dq = Some([DVec2::new(0.05, 0.0), DVec2::new(0.0, 1.2)]);
        let cut = gapped(AlphaMode::Cutout);
        assert!(
            cut.hit_footprint(q, dq).is_none(),
            "the ray goes through the gap"
        );
        // The blend's alpha is the footprint's (the material it reaches).
        let blend = gapped(AlphaMode::Blend)
            .hit_footprint(q, dq)
            .expect("some material");
        assert!(blend.alpha > 0.0 && blend.alpha < 0.5, "{}", blend.alpha);
        // Beside the gap a cutout hit is the material's full colour over
        // the filtered alpha (white), its alpha the footprint's.
        let h = cut
            .hit_footprint(DVec2::new(0.0, 7.2), dq)
            .expect("material");
        assert!(h.alpha < 1.0, "{}", h.alpha);
        let c = cut.rgb(&h) / h.alpha;
        assert!((c - Vec3::ONE).abs().max_element() < 1e-3, "{c}");
    }

    #[test]
    fn a_footprint_stops_at_the_materials_inner_edge() {
        let mut d = gapped(AlphaMode::Blend);
        d.material_inner = 3.0;
        // 0.5 r_s from the edge, reaching 2 r_s along the radius: shrunk
        // to reach 0.5; across the ring it is left alone.
        let q = DVec2::new(3.5, 0.0);
        let dq = [DVec2::new(2.0, 0.0), DVec2::new(0.0, 0.1)];
        let s = d.short_of_the_hole(q, 3.5, dq);
        assert!(
            (s[0].x - 0.5).abs() < 1e-12 && (s[1].y - 0.025).abs() < 1e-12,
            "{s:?}"
        );
        let far = d.short_of_the_hole(DVec2::new(0.0, 8.0), 8.0, dq);
        assert_eq!(far, dq);
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
        d.material = DiskMaterial::Rgb(Texture::from_image(image::DynamicImage::ImageRgba8(img)));
        let (lo, hi) = d.material_radii();
        let texel = 20.0 / n as f64;
        assert!(lo <= 4.0 && lo > 4.0 - 3.0 * texel, "{lo}");
        assert!(hi >= 6.0 && hi < 6.0 + 3.0 * texel, "{hi}");
        d.inner = 5.0;
        assert_eq!(d.material_radii().0, 5.0);
    }

    #[test]
    fn material_radii_of_a_single_opaque_texel() {
        // One texel whose centre is the disk's centre: opaque, not empty.
        let img = image::RgbaImage::from_pixel(1, 1, image::Rgba([255, 255, 255, 255]));
        let mut d = disk();
        d.inner = 0.0;
        d.material = DiskMaterial::Rgb(Texture::from_image(image::DynamicImage::ImageRgba8(img)));
        assert_eq!(d.material_radii(), (0.0, 10.0));
    }

    #[test]
    fn annulus_bounds() {
        let d = disk();
        assert!(rgb_at(&d, -0.5, 0.5).is_none(), "inside inner radius");
        assert!(
            rgb_at(&d, -9.0, 9.0).is_none(),
            "in the square, outside the circle"
        );
        assert!(rgb_at(&d, -7.0, 7.0).is_some());
    }
}
