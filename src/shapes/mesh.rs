//! Triangle meshes (from OBJ files) with a BVH.

use super::Hit;
use super::bvh::{Aabb, Bvh};
use glam::{DAffine3, DVec3};
use std::path::Path;

/// A triangle mesh in scene units.
#[derive(Clone, Debug)]
pub struct Mesh {
    positions: Vec<DVec3>,
    normals: Option<Vec<DVec3>>,
    uvs: Option<Vec<(f64, f64)>>,
    triangles: Vec<[u32; 3]>,
    bvh: Bvh,
}

impl Mesh {
    /// A mesh from vertices and triangles (indices into them), with optional
    /// per-vertex normals and texture coordinates.
    pub fn new(
        positions: Vec<DVec3>,
        triangles: Vec<[u32; 3]>,
        normals: Option<Vec<DVec3>>,
        uvs: Option<Vec<(f64, f64)>>,
    ) -> Mesh {
        let boxes: Vec<Aabb> = triangles
            .iter()
            .map(|t| {
                t.iter()
                    .fold(Aabb::EMPTY, |b, &i| b.with(positions[i as usize]))
            })
            .collect();
        let bvh = Bvh::build(&boxes);
        Mesh {
            positions,
            normals,
            uvs,
            triangles,
            bvh,
        }
    }

    /// Loads every object of an OBJ file (triangulated), placed by
    /// `transform` (model units -> scene units). Without normals in the
    /// file, `smooth` computes vertex normals (area-weighted face normals)
    /// instead of shading each face flat.
    pub fn load_obj(path: &Path, transform: DAffine3, smooth: bool) -> Result<Mesh, String> {
        let opts = tobj::LoadOptions {
            triangulate: true,
            single_index: true,
            ..Default::default()
        };
        let bytes = crate::inputs::read(path).map_err(|e| e.to_string())?;
        // Materials are not read: the scene gives the surface.
        let (models, _) = tobj::load_obj_buf(&mut std::io::Cursor::new(bytes), &opts, |_| {
            Err(tobj::LoadError::OpenFileFailed)
        })
        .map_err(|e| e.to_string())?;
        let (mut pos, mut nrm, mut uv, mut tris) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let (mut all_normals, mut all_uvs) = (true, true);
        let normal_matrix = transform.matrix3.inverse().transpose();
        for m in &models {
            let mesh = &m.mesh;
            let base = pos.len() as u32;
            for p in mesh.positions.chunks_exact(3) {
                pos.push(transform.transform_point3(DVec3::new(
                    p[0] as f64,
                    p[1] as f64,
                    p[2] as f64,
                )));
            }
            let n_verts = mesh.positions.len() / 3;
            if mesh.normals.len() == 3 * n_verts {
                nrm.extend(mesh.normals.chunks_exact(3).map(|n| {
                    (normal_matrix * DVec3::new(n[0] as f64, n[1] as f64, n[2] as f64))
                        .normalize_or_zero()
                }));
            } else {
                all_normals = false;
            }
            if mesh.texcoords.len() == 2 * n_verts {
                uv.extend(
                    mesh.texcoords
                        .chunks_exact(2)
                        .map(|t| (t[0] as f64, 1.0 - t[1] as f64)),
                );
            } else {
                all_uvs = false;
            }
            for t in mesh.indices.chunks_exact(3) {
                tris.push([base + t[0], base + t[1], base + t[2]]);
            }
        }
        if tris.is_empty() {
            return Err("has no faces (no f lines)".into());
        }
        // A NaN or infinite vertex would make its triangles vanish
        // silently: name the line.
        let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
        if models.iter().any(|m| {
            !finite(&m.mesh.positions) || !finite(&m.mesh.normals) || !finite(&m.mesh.texcoords)
        }) {
            return Err(non_finite_line(path));
        }
        if let Some(p) = pos.iter().find(|p| !p.is_finite()) {
            return Err(format!(
                "a vertex placed by position, rotation and scale is not finite ({p}): the scale is too large"
            ));
        }
        // Lines, points and repeated or collinear vertices make triangles
        // of no area, which no ray meets: such a file has no faces.
        let area = |&[a, b, c]: &[u32; 3]| {
            let (a, b, c) = (pos[a as usize], pos[b as usize], pos[c as usize]);
            (b - a).cross(c - a).length_squared()
        };
        if !tris.iter().any(|t| area(t) > 0.0) {
            return Err(format!(
                "has no faces: its {} triangle(s) all have zero area (only lines, points or repeated vertices)",
                tris.len()
            ));
        }
        let normals = if all_normals {
            Some(nrm)
        } else if smooth {
            let mut n = vec![DVec3::ZERO; pos.len()];
            for &[a, b, c] in &tris {
                let face =
                    (pos[b as usize] - pos[a as usize]).cross(pos[c as usize] - pos[a as usize]);
                for i in [a, b, c] {
                    n[i as usize] += face;
                }
            }
            Some(n.into_iter().map(|v| v.normalize_or_zero()).collect())
        } else {
            None
        };
        Ok(Mesh::new(pos, tris, normals, all_uvs.then_some(uv)))
    }
}

/// The first line of an OBJ file whose vertex, normal or texture
/// coordinate is not a finite number, as an error message.
fn non_finite_line(path: &Path) -> String {
    let text = crate::inputs::read_to_string(path).unwrap_or_default();
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let what = match words.next() {
            Some("v") => "vertex",
            Some("vn") => "normal",
            Some("vt") => "texture coordinate",
            _ => continue,
        };
        if words.any(|w| w.parse::<f32>().map_or(true, |x| !x.is_finite())) {
            return format!(
                "line {}: {what} {:?}: expected finite numbers",
                i + 1,
                line.trim()
            );
        }
    }
    "a vertex, normal or texture coordinate is not a finite number".into()
}

impl Mesh {
    /// Everything the GPU backend needs: positions, normals, texture
    /// coordinates, triangles and the BVH.
    #[allow(clippy::type_complexity)]
    pub(crate) fn gpu_parts(
        &self,
    ) -> (
        &[DVec3],
        Option<&[DVec3]>,
        Option<&[(f64, f64)]>,
        &[[u32; 3]],
        &super::bvh::Bvh,
    ) {
        (
            &self.positions,
            self.normals.as_deref(),
            self.uvs.as_deref(),
            &self.triangles,
            &self.bvh,
        )
    }

    /// Whether triangles `a` and `b` are one or share a vertex.
    pub fn adjacent(&self, a: u32, b: u32) -> bool {
        let (ta, tb) = (self.triangles[a as usize], self.triangles[b as usize]);
        a == b || ta.iter().any(|v| tb.contains(v))
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Nearest and farthest vertex distance from the origin (the nearest is
    /// a lower bound of the surface's distance: a face can pass closer).
    pub fn radial_extent(&self) -> (f64, f64) {
        let far = self
            .positions
            .iter()
            .map(|p| p.length())
            .fold(0.0, f64::max);
        // Bound the near side by the distance to the mesh's bounding box.
        let b = self.positions.iter().fold(Aabb::EMPTY, |b, &p| b.with(p));
        let near = DVec3::ZERO.clamp(b.min, b.max).length();
        (near, far)
    }

    /// Möller-Trumbore: parameter t in (0, t_max] and barycentrics of the
    /// chord a + t d with triangle `i`, either side.
    #[inline]
    fn triangle(&self, i: u32, a: DVec3, d: DVec3, t_max: f64) -> Option<(f64, f64, f64)> {
        let [i0, i1, i2] = self.triangles[i as usize];
        let (p0, p1, p2) = (
            self.positions[i0 as usize],
            self.positions[i1 as usize],
            self.positions[i2 as usize],
        );
        let (e1, e2) = (p1 - p0, p2 - p0);
        let pv = d.cross(e2);
        let det = e1.dot(pv);
        if det.abs() < 1e-300 {
            return None;
        }
        let inv = 1.0 / det;
        let tv = a - p0;
        let u = tv.dot(pv) * inv;
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let qv = tv.cross(e1);
        let v = d.dot(qv) * inv;
        if v < 0.0 || u + v > 1.0 {
            return None;
        }
        let t = e2.dot(qv) * inv;
        (t > 1e-12 && t <= t_max).then_some((t, u, v))
    }

    /// Nearest crossing of the chord a -> b.
    pub fn intersect(&self, a: DVec3, b: DVec3) -> Option<Hit> {
        let d = b - a;
        let (t, i) = self.bvh.nearest(a, d, 1.0, |i, t_max| {
            self.triangle(i, a, d, t_max).map(|h| h.0)
        })?;
        let (_, u, v) = self.triangle(i, a, d, 1.0)?;
        let [i0, i1, i2] = self.triangles[i as usize];
        let w = 1.0 - u - v;
        let normal = match &self.normals {
            Some(n) => {
                (n[i0 as usize] * w + n[i1 as usize] * u + n[i2 as usize] * v).normalize_or_zero()
            }
            None => DVec3::ZERO,
        };
        let normal = if normal == DVec3::ZERO {
            let (p0, p1, p2) = (
                self.positions[i0 as usize],
                self.positions[i1 as usize],
                self.positions[i2 as usize],
            );
            (p1 - p0).cross(p2 - p0).normalize()
        } else {
            normal
        };
        let uv = match &self.uvs {
            Some(t) => {
                let (a0, a1, a2) = (t[i0 as usize], t[i1 as usize], t[i2 as usize]);
                (
                    a0.0 * w + a1.0 * u + a2.0 * v,
                    a0.1 * w + a1.1 * u + a2.1 * v,
                )
            }
            None => (u, v),
        };
        Some(Hit {
            s: t,
            point: a + d * t,
            normal,
            uv,
            part: i,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> Mesh {
        // The unit square in the plane y = 5, two triangles, normal -y.
        let v = vec![
            DVec3::new(0.0, 5.0, 0.0),
            DVec3::new(1.0, 5.0, 0.0),
            DVec3::new(1.0, 5.0, 1.0),
            DVec3::new(0.0, 5.0, 1.0),
        ];
        Mesh::new(v, vec![[0, 2, 1], [0, 3, 2]], None, None)
    }

    #[test]
    fn segment_meets_triangles_inside_and_misses_outside() {
        let m = quad();
        let h = m
            .intersect(DVec3::new(0.25, 0.0, 0.75), DVec3::new(0.25, 10.0, 0.75))
            .unwrap();
        assert!((h.s - 0.5).abs() < 1e-12);
        assert!((h.point - DVec3::new(0.25, 5.0, 0.75)).length() < 1e-12);
        assert!((h.normal.y.abs() - 1.0).abs() < 1e-12);
        assert!(
            m.intersect(DVec3::new(1.25, 0.0, 0.5), DVec3::new(1.25, 10.0, 0.5))
                .is_none()
        );
        assert!(
            m.intersect(DVec3::new(0.5, 0.0, 0.5), DVec3::new(0.5, 4.9, 0.5))
                .is_none(),
            "too short"
        );
        // Either side.
        assert!(
            m.intersect(DVec3::new(0.5, 10.0, 0.5), DVec3::new(0.5, 0.0, 0.5))
                .is_some()
        );
    }

    #[test]
    fn hits_on_triangles_sharing_a_vertex_are_one_surface() {
        // The quad's two triangles share an edge; a copy of its vertices
        // (as an OBJ's seam of the texture makes) is another surface.
        let mut v: Vec<DVec3> = quad().positions.clone();
        v.extend(v.clone());
        let m = super::super::Shape::Mesh(std::sync::Arc::new(Mesh::new(
            v,
            vec![[0, 2, 1], [0, 3, 2], [4, 6, 5]],
            None,
            None,
        )));
        let at = |x: f64, z: f64| {
            m.intersect(DVec3::new(x, 0.0, z), DVec3::new(x, 10.0, z))
                .unwrap()
        };
        let (a, b) = (at(0.75, 0.25), at(0.25, 0.75));
        assert_ne!(a.part, b.part);
        assert!(m.continuous(&a, &b) && m.continuous(&a, &a));
        let copy = Hit { part: 2, ..a };
        assert!(!m.continuous(&copy, &b));
    }

    #[test]
    fn nearest_of_stacked_layers_wins() {
        // Ten parallel squares at y = 1..10; from y = 0 the first is nearest.
        let mut v = Vec::new();
        let mut t = Vec::new();
        for k in 0..10u32 {
            let y = 1.0 + k as f64;
            v.extend([
                DVec3::new(0.0, y, 0.0),
                DVec3::new(1.0, y, 0.0),
                DVec3::new(0.0, y, 1.0),
            ]);
            t.push([3 * k, 3 * k + 1, 3 * k + 2]);
        }
        let m = Mesh::new(v, t, None, None);
        let h = m
            .intersect(DVec3::new(0.2, 0.0, 0.2), DVec3::new(0.2, 20.0, 0.2))
            .unwrap();
        assert!((h.point.y - 1.0).abs() < 1e-12);
        let h = m
            .intersect(DVec3::new(0.2, 20.0, 0.2), DVec3::new(0.2, 0.0, 0.2))
            .unwrap();
        assert!((h.point.y - 10.0).abs() < 1e-12);
    }

    #[test]
    fn obj_loads_with_transform() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.obj");
        std::fs::write(&p, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\n").unwrap();
        let t = DAffine3::from_scale_rotation_translation(
            DVec3::splat(2.0),
            glam::DQuat::IDENTITY,
            DVec3::new(0.0, 0.0, 10.0),
        );
        let m = Mesh::load_obj(&p, t, true).unwrap();
        assert_eq!(m.triangle_count(), 2);
        let (near, far) = m.radial_extent();
        assert!((near - 10.0).abs() < 1e-12 && (far - 12.0).abs() < 1e-12);
        std::fs::write(&p, "v 0 0 0\n").unwrap();
        assert!(Mesh::load_obj(&p, t, false).is_err());
        // Vertices that are not finite numbers are named by their line.
        for (bad, line) in [("v nan 0 0", 2), ("v 0 1e40 0", 2), ("vn inf 0 1", 5)] {
            let text = format!("v 0 0 0\n{bad}\nv 0 1 0\nv 0 0 1\nf 1 2 3\n");
            let text = if bad.starts_with("vn") {
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn inf 0 1\nvn 0 0 1\nf 1//1 2//2 3//3\n"
                    .to_string()
            } else {
                text
            };
            std::fs::write(&p, text).unwrap();
            let e = Mesh::load_obj(&p, t, false).unwrap_err();
            assert!(e.contains(&format!("line {line}:")), "{bad}: {e}");
        }
        std::fs::write(&p, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        let huge =
            DAffine3::from_scale(DVec3::splat(1e300)) * DAffine3::from_scale(DVec3::splat(1e300));
        let e = Mesh::load_obj(&p, huge, false).unwrap_err();
        assert!(e.contains("not finite"), "{e}");
    }
}
