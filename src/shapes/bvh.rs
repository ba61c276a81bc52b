//! A bounding volume hierarchy over triangles, built with binned surface-area
//! heuristic splits and queried with a segment.

use glam::DVec3;

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: DVec3,
    /// Largest corner.
    pub max: DVec3,
}

impl Aabb {
    /// The empty box.
    pub const EMPTY: Aabb = Aabb {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    /// Grown to contain `p`.
    pub fn with(self, p: DVec3) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// Union of two boxes.
    pub fn union(self, o: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    fn area(&self) -> f64 {
        let d = (self.max - self.min).max(DVec3::ZERO);
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    /// Entry parameter of the segment a + t d (t in [0, t_max]) if it meets
    /// the box; `inv` is 1/d per component.
    #[inline]
    pub fn hit(&self, a: DVec3, inv: DVec3, t_max: f64) -> Option<f64> {
        let t0 = (self.min - a) * inv;
        let t1 = (self.max - a) * inv;
        let near = t0.min(t1).max_element().max(0.0);
        let far = t0.max(t1).min_element().min(t_max);
        (near <= far).then_some(near)
    }
}

#[derive(Clone, Copy, Debug)]
struct Node {
    bounds: Aabb,
    /// Leaf: first triangle index; inner: index of the second child (the
    /// first child follows the node).
    start: u32,
    /// Triangles in a leaf; 0 for an inner node.
    count: u32,
}

/// A BVH over items given by their bounding boxes; the items are reordered
/// so each leaf covers a contiguous range of `order`.
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<Node>,
    /// Item indices in leaf order.
    pub order: Vec<u32>,
}

/// A node as the GPU backend stores it: min, start, max, count (8 words,
/// floats as bits).
pub(crate) type GpuNode = [u32; 8];

impl Bvh {
    /// The nodes and the triangle order, for the GPU backend.
    pub(crate) fn gpu_parts(&self) -> (Vec<GpuNode>, &[u32]) {
        let nodes = self
            .nodes
            .iter()
            .map(|n| {
                let (a, b) = (n.bounds.min.as_vec3(), n.bounds.max.as_vec3());
                [
                    a.x.to_bits(),
                    a.y.to_bits(),
                    a.z.to_bits(),
                    n.start,
                    b.x.to_bits(),
                    b.y.to_bits(),
                    b.z.to_bits(),
                    n.count,
                ]
            })
            .collect();
        (nodes, &self.order)
    }
}

const BINS: usize = 12;
const LEAF: usize = 4;

impl Bvh {
    /// Builds over `boxes`.
    pub fn build(boxes: &[Aabb]) -> Bvh {
        let centroids: Vec<DVec3> = boxes.iter().map(|b| (b.min + b.max) * 0.5).collect();
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(2 * boxes.len().max(1)),
            order: (0..boxes.len() as u32).collect(),
        };
        if !boxes.is_empty() {
            bvh.split(boxes, &centroids, 0, boxes.len());
        }
        bvh
    }

    fn split(&mut self, boxes: &[Aabb], c: &[DVec3], lo: usize, hi: usize) -> usize {
        let bounds = self.order[lo..hi]
            .iter()
            .fold(Aabb::EMPTY, |b, &i| b.union(boxes[i as usize]));
        let me = self.nodes.len();
        self.nodes.push(Node {
            bounds,
            start: lo as u32,
            count: (hi - lo) as u32,
        });
        if hi - lo <= LEAF {
            return me;
        }
        let cb = self.order[lo..hi]
            .iter()
            .fold(Aabb::EMPTY, |b, &i| b.with(c[i as usize]));
        let extent = cb.max - cb.min;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        if extent[axis] <= 0.0 {
            return me;
        }
        // Binned SAH along the widest centroid axis.
        let bin_of = |i: u32| {
            (((c[i as usize][axis] - cb.min[axis]) / extent[axis] * BINS as f64) as usize)
                .min(BINS - 1)
        };
        let mut bin_box = [Aabb::EMPTY; BINS];
        let mut bin_n = [0usize; BINS];
        for &i in &self.order[lo..hi] {
            let b = bin_of(i);
            bin_box[b] = bin_box[b].union(boxes[i as usize]);
            bin_n[b] += 1;
        }
        let (mut best, mut best_cost) = (0, f64::INFINITY);
        for k in 0..BINS - 1 {
            let (l, ln) = (0..=k).fold((Aabb::EMPTY, 0), |(b, n), j| {
                (b.union(bin_box[j]), n + bin_n[j])
            });
            let (r, rn) = (k + 1..BINS).fold((Aabb::EMPTY, 0), |(b, n), j| {
                (b.union(bin_box[j]), n + bin_n[j])
            });
            if ln == 0 || rn == 0 {
                continue;
            }
            let cost = l.area() * ln as f64 + r.area() * rn as f64;
            if cost < best_cost {
                best_cost = cost;
                best = k;
            }
        }
        if !best_cost.is_finite() {
            return me;
        }
        let slice = &mut self.order[lo..hi];
        let mut mid = 0;
        for j in 0..slice.len() {
            if bin_of(slice[j]) <= best {
                slice.swap(j, mid);
                mid += 1;
            }
        }
        let mid = lo + mid;
        self.split(boxes, c, lo, mid);
        let right = self.split(boxes, c, mid, hi);
        self.nodes[me].start = right as u32;
        self.nodes[me].count = 0;
        me
    }

    /// Visits the items whose boxes the segment a + t d, t in [0, t_max],
    /// meets, nearer boxes first; `test` returns an item's hit parameter
    /// (below the current `t_max`, which it is given), and each hit
    /// shortens the segment. Returns the nearest (t, item).
    pub fn nearest(
        &self,
        a: DVec3,
        d: DVec3,
        mut t_max: f64,
        mut test: impl FnMut(u32, f64) -> Option<f64>,
    ) -> Option<(f64, u32)> {
        if self.nodes.is_empty() {
            return None;
        }
        let inv = DVec3::ONE / d;
        let mut best = None;
        let mut stack = [0u32; 64];
        stack[0] = 0;
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let idx = stack[top] as usize;
            let node = &self.nodes[idx];
            if node.bounds.hit(a, inv, t_max).is_none() {
                continue;
            }
            if node.count > 0 {
                for &i in &self.order[node.start as usize..(node.start + node.count) as usize] {
                    if let Some(t) = test(i, t_max)
                        && t < t_max
                    {
                        t_max = t;
                        best = Some((t, i));
                    }
                }
                continue;
            }
            let (first, second) = (idx + 1, node.start as usize);
            let dl = self.nodes[first].bounds.hit(a, inv, t_max);
            let dr = self.nodes[second].bounds.hit(a, inv, t_max);
            // Push the farther child first so the nearer is visited first.
            let order = match (dl, dr) {
                (Some(x), Some(y)) if x <= y => [Some(second), Some(first)],
                (Some(_), Some(_)) => [Some(first), Some(second)],
                (Some(_), None) => [None, Some(first)],
                (None, Some(_)) => [None, Some(second)],
                (None, None) => [None, None],
            };
            for child in order.into_iter().flatten() {
                // The depth of a binned-SAH tree over 2^32 items stays far
                // below the stack size.
                debug_assert!(top < stack.len());
                stack[top] = child as u32;
                top += 1;
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_nearest_of_many_boxes() {
        // Unit boxes along +x at x = 0, 2, 4, ...; a segment along +x from
        // x = -1 meets box 0 first.
        let boxes: Vec<Aabb> = (0..100)
            .map(|i| Aabb {
                min: DVec3::new(2.0 * i as f64, -0.5, -0.5),
                max: DVec3::new(2.0 * i as f64 + 1.0, 0.5, 0.5),
            })
            .collect();
        let bvh = Bvh::build(&boxes);
        let a = DVec3::new(-1.0, 0.0, 0.0);
        let d = DVec3::new(1000.0, 0.0, 0.0);
        let hit = bvh.nearest(a, d, 1.0, |i, t_max| {
            boxes[i as usize].hit(a, DVec3::ONE / d, t_max)
        });
        assert_eq!(hit.unwrap().1, 0);
        // From the far end backwards, the last box.
        let a = DVec3::new(300.0, 0.0, 0.0);
        let d = DVec3::new(-1000.0, 0.0, 0.0);
        let hit = bvh.nearest(a, d, 1.0, |i, t_max| {
            boxes[i as usize].hit(a, DVec3::ONE / d, t_max)
        });
        assert_eq!(hit.unwrap().1, 99);
        // A segment that passes beside them all.
        let a = DVec3::new(-1.0, 2.0, 0.0);
        assert!(
            bvh.nearest(a, DVec3::X * 1000.0, 1.0, |i, t| boxes[i as usize].hit(
                a,
                DVec3::ONE / (DVec3::X * 1000.0),
                t
            ))
            .is_none()
        );
    }

    #[test]
    fn every_item_appears_once() {
        let boxes: Vec<Aabb> = (0..1000)
            .map(|i| {
                let p = DVec3::new((i * 37 % 101) as f64, (i * 53 % 97) as f64, (i % 13) as f64);
                Aabb {
                    min: p,
                    max: p + DVec3::ONE,
                }
            })
            .collect();
        let bvh = Bvh::build(&boxes);
        let mut seen = bvh.order.clone();
        seen.sort();
        assert_eq!(seen, (0..1000).collect::<Vec<u32>>());
    }
}
