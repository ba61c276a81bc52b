//! Solid objects met by a ray's segments: spheres, rectangles and triangle
//! meshes. Lengths are in r_s; each step's segment is tested as the straight
//! chord between its ends (the assignment's polyline), nearest hit wins.

pub mod bvh;
pub mod mesh;

use glam::DVec3;
pub use mesh::Mesh;

/// Where a segment met a surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Fraction of the segment (0..1) at the hit.
    pub s: f64,
    /// The point.
    pub point: DVec3,
    /// Unit surface normal (outward for closed shapes; for a rectangle, its
    /// front side).
    pub normal: DVec3,
    /// Texture coordinates.
    pub uv: (f64, f64),
    /// Which piece of the surface: a mesh's triangle (0 for the others).
    pub part: u32,
}

/// A sphere.
#[derive(Clone, Debug)]
pub struct Sphere {
    /// Centre.
    pub center: DVec3,
    /// Radius.
    pub radius: f64,
    /// Orientation: the pole (texture v) and the direction of u = 0.
    pub pole: DVec3,
    /// Direction of texture u = 0 (perpendicular to the pole).
    pub meridian: DVec3,
}

impl Sphere {
    /// First crossing of the chord a -> b with the surface, entering or
    /// leaving (a ray that starts inside still meets the wall).
    pub fn intersect(&self, a: DVec3, b: DVec3) -> Option<Hit> {
        let d = b - a;
        let m = a - self.center;
        let qa = d.length_squared();
        let qb = m.dot(d);
        let qc = m.length_squared() - self.radius * self.radius;
        let disc = qb * qb - qa * qc;
        if qa == 0.0 || disc < 0.0 {
            return None;
        }
        let root = disc.sqrt();
        // Roots in a cancellation-free form.
        let q = -(qb + root.copysign(qb));
        let (t0, t1) = {
            let (x, y) = (q / qa, if q != 0.0 { qc / q } else { f64::INFINITY });
            (x.min(y), x.max(y))
        };
        let s = if t0 > 1e-12 && t0 <= 1.0 {
            t0
        } else if t1 > 1e-12 && t1 <= 1.0 {
            t1
        } else {
            return None;
        };
        let point = a + d * s;
        let normal = (point - self.center) / self.radius;
        let east = self.pole.cross(self.meridian);
        let (x, y, z) = (
            normal.dot(self.meridian),
            normal.dot(east),
            normal.dot(self.pole),
        );
        let u = y.atan2(x).rem_euclid(std::f64::consts::TAU) / std::f64::consts::TAU;
        let v = z.clamp(-1.0, 1.0).acos() / std::f64::consts::PI;
        Some(Hit {
            s,
            point,
            normal,
            uv: (u, v),
            part: 0,
        })
    }
}

/// A rectangle (a bounded plane).
#[derive(Clone, Debug)]
pub struct Rectangle {
    /// Centre.
    pub center: DVec3,
    /// Unit normal of the front side.
    pub normal: DVec3,
    /// Unit vector along the width (texture u).
    pub u_axis: DVec3,
    /// Half the width and height.
    pub half: (f64, f64),
}

impl Rectangle {
    /// Crossing of the chord a -> b with the rectangle.
    pub fn intersect(&self, a: DVec3, b: DVec3) -> Option<Hit> {
        let (da, db) = (
            (a - self.center).dot(self.normal),
            (b - self.center).dot(self.normal),
        );
        if da == db || (da > 0.0) == (db > 0.0) && db != 0.0 {
            return None;
        }
        let s = da / (da - db);
        if !(s > 1e-12 && s <= 1.0) {
            return None;
        }
        let point = a + (b - a) * s;
        let v_axis = self.normal.cross(self.u_axis);
        let r = point - self.center;
        let (x, y) = (r.dot(self.u_axis), r.dot(v_axis));
        if x.abs() > self.half.0 || y.abs() > self.half.1 {
            return None;
        }
        Some(Hit {
            s,
            point,
            normal: self.normal,
            uv: (0.5 + 0.5 * x / self.half.0, 0.5 - 0.5 * y / self.half.1),
            part: 0,
        })
    }
}

/// A solid object's geometry.
#[derive(Clone, Debug)]
pub enum Shape {
    /// A sphere.
    Sphere(Sphere),
    /// A rectangle.
    Rectangle(Rectangle),
    /// A triangle mesh with its BVH.
    Mesh(std::sync::Arc<Mesh>),
}

impl Shape {
    /// Nearest crossing of the chord a -> b.
    #[inline]
    pub fn intersect(&self, a: DVec3, b: DVec3) -> Option<Hit> {
        match self {
            Shape::Sphere(s) => s.intersect(a, b),
            Shape::Rectangle(r) => r.intersect(a, b),
            Shape::Mesh(m) => m.intersect(a, b),
        }
    }

    /// Whether hits `a` and `b` lie on one smooth piece of the surface, its
    /// texture coordinates continuous between them: always on a sphere or
    /// a rectangle; on a mesh, the same triangle or two sharing a vertex
    /// (an OBJ's vertex is shared only where its texture coordinates, and
    /// normal where the file gives one, agree: a seam of the texture parts
    /// the triangles either side).
    pub fn continuous(&self, a: &Hit, b: &Hit) -> bool {
        match self {
            Shape::Sphere(_) | Shape::Rectangle(_) => true,
            Shape::Mesh(m) => m.adjacent(a.part, b.part),
        }
    }

    /// Nearest and farthest distance of the shape from the origin (the hole).
    pub fn radial_extent(&self) -> (f64, f64) {
        match self {
            Shape::Sphere(s) => {
                let c = s.center.length();
                ((c - s.radius).max(0.0), c + s.radius)
            }
            Shape::Rectangle(r) => {
                let v = r.normal.cross(r.u_axis);
                let corners = [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)].map(|(i, j)| {
                    (r.center + r.u_axis * (i * r.half.0) + v * (j * r.half.1)).length()
                });
                let far = corners.iter().cloned().fold(0.0, f64::max);
                // Distance from the origin to the rectangle, clamped in-plane.
                let p = -r.center;
                let (x, y) = (
                    p.dot(r.u_axis).clamp(-r.half.0, r.half.0),
                    p.dot(v).clamp(-r.half.1, r.half.1),
                );
                let near = (r.center + r.u_axis * x + v * y).length();
                (near, far)
            }
            Shape::Mesh(m) => m.radial_extent(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere() -> Sphere {
        Sphere {
            center: DVec3::new(0.0, 10.0, 0.0),
            radius: 2.0,
            pole: DVec3::Z,
            meridian: DVec3::X,
        }
    }

    #[test]
    fn segment_enters_sphere_at_the_near_side() {
        let h = sphere()
            .intersect(DVec3::ZERO, DVec3::new(0.0, 20.0, 0.0))
            .unwrap();
        assert!((h.s - 0.4).abs() < 1e-12);
        assert!((h.point - DVec3::new(0.0, 8.0, 0.0)).length() < 1e-12);
        assert!((h.normal + DVec3::Y).length() < 1e-12);
    }

    #[test]
    fn segment_short_of_or_beside_the_sphere_misses() {
        assert!(
            sphere()
                .intersect(DVec3::ZERO, DVec3::new(0.0, 7.9, 0.0))
                .is_none()
        );
        assert!(
            sphere()
                .intersect(DVec3::new(2.1, 0.0, 0.0), DVec3::new(2.1, 20.0, 0.0))
                .is_none()
        );
        // Grazing: tangent at x = 2 touches.
        let h = sphere()
            .intersect(DVec3::new(1.999, 0.0, 0.0), DVec3::new(1.999, 20.0, 0.0))
            .unwrap();
        assert!((h.point.y - 10.0).abs() < 0.1);
    }

    #[test]
    fn segment_from_inside_meets_the_wall() {
        let h = sphere()
            .intersect(DVec3::new(0.0, 10.0, 0.0), DVec3::new(0.0, 10.0, 4.0))
            .unwrap();
        assert!((h.s - 0.5).abs() < 1e-12);
    }

    #[test]
    fn sphere_texture_coordinates() {
        // +x (the meridian) is u = 0, the pole v = 0.
        let s = sphere();
        let h = s
            .intersect(DVec3::new(5.0, 10.0, 0.0), DVec3::new(0.0, 10.0, 0.0))
            .unwrap();
        assert!(h.uv.0.abs() < 1e-12 && (h.uv.1 - 0.5).abs() < 1e-12);
        let h = s
            .intersect(DVec3::new(0.0, 10.0, 5.0), DVec3::new(0.0, 10.0, 0.0))
            .unwrap();
        assert!(h.uv.1.abs() < 1e-9);
    }

    #[test]
    fn rectangle_bounds_and_sides() {
        let r = Rectangle {
            center: DVec3::new(0.0, 5.0, 0.0),
            normal: -DVec3::Y,
            u_axis: DVec3::X,
            half: (1.0, 2.0),
        };
        let h = r
            .intersect(DVec3::new(0.5, 0.0, 1.5), DVec3::new(0.5, 10.0, 1.5))
            .unwrap();
        assert!((h.s - 0.5).abs() < 1e-12);
        assert!((h.uv.0 - 0.75).abs() < 1e-12);
        assert!(
            r.intersect(DVec3::new(1.5, 0.0, 0.0), DVec3::new(1.5, 10.0, 0.0))
                .is_none()
        );
        assert!(
            r.intersect(DVec3::new(0.0, 0.0, 0.0), DVec3::new(0.0, 4.0, 0.0))
                .is_none()
        );
        let (near, far) = Shape::Rectangle(r).radial_extent();
        assert!((near - 5.0).abs() < 1e-12 && (far - (1.0f64 + 4.0 + 25.0).sqrt()).abs() < 1e-12);
    }
}
