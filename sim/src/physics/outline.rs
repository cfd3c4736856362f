//! The geometry of a wedge-fronted robot ([`RobotShape::Wedge`]): the
//! convex hull of its round back (radius `r` around the centre) and its tip
//! (`l` straight ahead), and its contacts with circles, with other wedges
//! and with walls.
//!
//! In the robot's frame (x ahead, y to its right), the faces touch the
//! circle at the tangent points `r (cos b, +-sin b)` with `cos b = r / l`;
//! each face is `f = sqrt(l^2 - r^2)` long. The outline is the
//! intersection of the half-planes `p . e(t) <= r` for the angles `t` of
//! the round back (`b <= |t| <= pi`; the faces' lines are its two end
//! tangents), so the depth of a point inside is its distance to the
//! nearest of those lines, and a point outside is nearest to the arc, a
//! face or the tip by the region it lies in ([`Outline::distance`]).
//!
//! Two convex bodies overlap when the difference of their centres lies in
//! the Minkowski difference of their outlines. Of two wedges with tips at
//! `a` and `b` (from their centres) that is the hull of four circles:
//! radius `2r` at 0, `r` at `a`, `r` at `-b` and a point at `a - b`; the
//! depth of the overlap and the direction that separates them are the
//! minimum over unit `n` of `max_k (r_k + c_k . n) - delta . n`
//! ([`hull_depth`]), found exactly among the candidates where one circle's
//! term is least or two terms are equal.
//!
//! Contacts move bodies by translation only: a contact never turns a
//! robot, whose heading its controller alone sets (as on the discs).

use crate::base::vec2::Vec2;
use crate::config::robot_shape::RobotShape;

/// A wedge's outline with what its contacts need precomputed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outline {
    /// The round back's radius.
    radius: f64,
    /// The tip's distance from the centre.
    tip: f64,
    /// Cosine and sine of the tangent points' angle off the heading.
    cos_b: f64,
    sin_b: f64,
    /// A face's length.
    face: f64,
}

impl Outline {
    /// The outline of `shape` for robots of `robot_radius`; `None` for the
    /// disc, whose contacts are the circles'.
    pub fn of(shape: RobotShape, robot_radius: f64) -> Option<Outline> {
        match shape {
            RobotShape::Disc => None,
            RobotShape::Wedge { tip } => Some(Outline::new(robot_radius, tip)),
        }
    }

    /// A round back of `radius` and a tip `tip` ahead (`tip > radius`).
    pub fn new(radius: f64, tip: f64) -> Outline {
        let cos_b = radius / tip;
        Outline {
            radius,
            tip,
            cos_b,
            sin_b: (1.0 - cos_b * cos_b).sqrt(),
            face: (tip * tip - radius * radius).sqrt(),
        }
    }

    /// The round back's radius.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// The tip's distance from the centre.
    pub fn tip(&self) -> f64 {
        self.tip
    }

    /// The wedge's full angle at the tip, radians: `pi - 2 b`.
    pub fn tip_angle(&self) -> f64 {
        std::f64::consts::PI - 2.0 * self.cos_b.acos()
    }

    /// The tangent point on the robot's right (`y > 0`), in its frame; the
    /// left one is its mirror image.
    pub fn tangent_point(&self) -> Vec2 {
        Vec2::new(self.radius * self.cos_b, self.radius * self.sin_b)
    }

    /// How far the outline of a robot facing `direction` reaches along the
    /// unit vector `n` from its centre: `max(r, l (n . direction))`.
    #[inline]
    pub fn support(&self, direction: Vec2, n: Vec2) -> f64 {
        self.radius.max(self.tip * n.dot(direction))
    }

    /// The signed distance from the outline to `q` (in the robot's frame;
    /// positive outside, minus the depth inside) and the outline's outward
    /// unit normal at the nearest boundary point (for a point inside: the
    /// direction that takes it out soonest; at the centre, straight back).
    pub fn distance(&self, q: Vec2) -> (f64, Vec2) {
        // By symmetry, work on the right half (y >= 0) and mirror back.
        let y = q.y.abs();
        let mirror = if q.y < 0.0 { -1.0 } else { 1.0 };
        // Along the right face, from its tangent point towards the tip.
        let along = q.x * self.sin_b - y * self.cos_b;
        let (d, n) = if along <= 0.0 {
            // Nearest to the round back.
            let len = q.length();
            let n = if len > 0.0 {
                Vec2::new(q.x / len, y / len)
            } else {
                Vec2::new(-1.0, 0.0)
            };
            (len - self.radius, n)
        } else if along < self.face {
            let n = Vec2::new(self.cos_b, self.sin_b);
            (q.x * n.x + y * n.y - self.radius, n)
        } else {
            // Beyond the face's end: nearest to the tip (always outside).
            let v = Vec2::new(q.x - self.tip, y);
            let len = v.length();
            let n = if len > 0.0 {
                v * (1.0 / len)
            } else {
                Vec2::new(1.0, 0.0)
            };
            (len, n)
        };
        (d, Vec2::new(n.x, n.y * mirror))
    }

    /// How deep a circle of radius `rho` at `delta` from the centre of a
    /// robot facing `direction` overlaps its outline (negative: the gap),
    /// and the unit normal along which the circle leaves it, in the world.
    #[inline]
    pub fn circle_depth(&self, direction: Vec2, delta: Vec2, rho: f64) -> (f64, Vec2) {
        let right = Vec2::new(-direction.y, direction.x);
        let local = Vec2::new(delta.dot(direction), delta.dot(right));
        let (d, n) = self.distance(local);
        (rho - d, direction * n.x + right * n.y)
    }

    /// How deep two wedges overlap (negative: the gap between them): robot
    /// `b`'s centre at `delta` from robot `a`'s, facing `dir_b` and `dir_a`;
    /// and the unit normal along which `b` leaves `a`.
    pub fn pair_depth(&self, dir_a: Vec2, dir_b: Vec2, delta: Vec2) -> (f64, Vec2) {
        self.pair_depth_until(dir_a, dir_b, delta, f64::NEG_INFINITY)
    }

    /// [`Outline::pair_depth`], but stopping as soon as the depth is known
    /// to be at most `stop` (below infinity), with a depth at most `stop` (for a pair that
    /// does not touch, the first normal tried, along the centre line,
    /// often shows it).
    pub fn pair_depth_until(
        &self,
        dir_a: Vec2,
        dir_b: Vec2,
        delta: Vec2,
        stop: f64,
    ) -> (f64, Vec2) {
        let (a, b) = (dir_a * self.tip, dir_b * self.tip);
        let r = self.radius;
        hull_depth_until(
            &[(Vec2::ZERO, 2.0 * r), (a, r), (-b, r), (a - b, 0.0)],
            delta,
            stop,
            true,
        )
    }
}

/// For the hull `M` of the circles (centre, radius) and a point `delta`:
/// the depth of `delta` in `M` (negative: minus its distance from `M`) and
/// the unit `n` of least `max_k (r_k + c_k . n) - delta . n`, the outward
/// normal of `M`'s boundary nearest to `delta`. The minimum over the unit
/// circle lies where one term is least (`n` along `delta - c_k`) or where
/// two terms are equal; all of those are tried, in a fixed order, and the
/// first least kept.
pub fn hull_depth<const N: usize>(circles: &[(Vec2, f64); N], delta: Vec2) -> (f64, Vec2) {
    hull_depth_until(circles, delta, f64::NEG_INFINITY, false)
}

/// [`hull_depth`], stopping once the least value so far is at most
/// `stop`: then the depth is at most `stop` too, and that value is
/// returned (the candidates come in the same order, so a search that does
/// not stop returns exactly [`hull_depth`]'s). The circles come as an
/// array (at least one), whose loops the compiler unrolls. With `centred`
/// the first circle's centre is the origin, and its term of the search,
/// `r + 0 . n`, is taken as `r`: exactly that for a radius other than 0
/// and a finite `n` (every candidate's).
fn hull_depth_until<const N: usize>(
    circles: &[(Vec2, f64); N],
    delta: Vec2,
    stop: f64,
    centred: bool,
) -> (f64, Vec2) {
    debug_assert!(!centred || circles[0].0 == Vec2::ZERO);
    let term = |(c, r): (Vec2, f64), n: Vec2| r + c.dot(n);
    // The greater of two terms. No term is NaN, nor -0 (a radius, at
    // least 0, plus a dot product is -0 only for two -0s), so which of two
    // equal terms is kept makes no difference.
    let greater = |a: f64, b: f64| if a > b { a } else { b };
    let value = |n: Vec2| {
        let first = if centred {
            circles[0].1
        } else {
            term(circles[0], n)
        };
        circles[1..]
            .iter()
            .fold(first, |most, &circle| greater(most, term(circle, n)))
            - delta.dot(n)
    };
    let mut best = (f64::INFINITY, Vec2::new(1.0, 0.0));
    // Whether the search can stop: the least value so far is at most
    // `stop`, which it can newly be only when a candidate lowers it (for
    // a `stop` below infinity, as every caller's is).
    let mut consider = |n: Vec2| {
        let v = value(n);
        if v < best.0 {
            best = (v, n);
            return v <= stop;
        }
        false
    };
    for &(c, _) in circles {
        let w = delta - c;
        let len = w.length();
        if len > 0.0 && consider(w * (1.0 / len)) {
            return best;
        }
    }
    for (k, &(ck, rk)) in circles.iter().enumerate() {
        for &(cj, rj) in &circles[k + 1..] {
            // r_k + c_k . n = r_j + c_j . n  <=>  (c_k - c_j) . n = r_j - r_k
            let e = ck - cj;
            let len = e.length();
            if len == 0.0 {
                continue;
            }
            let along = (rj - rk) / len;
            if along.abs() > 1.0 {
                continue;
            }
            let (u, across) = (e * (1.0 / len), (1.0 - along * along).sqrt());
            let perp = Vec2::new(-u.y, u.x);
            if consider(u * along + perp * across) || consider(u * along - perp * across) {
                return best;
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::rng::SimRng;
    use rand::{RngExt, SeedableRng};

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    /// The default wedge's proportions: a round back of 10, the tip at 13.
    fn wedge() -> Outline {
        Outline::new(10.0, 13.0)
    }

    #[test]
    fn the_faces_are_tangent_to_the_round_back() {
        let o = wedge();
        let t = o.tangent_point();
        assert!(close(t.length(), 10.0));
        // The face from the tangent point to the tip is perpendicular to
        // the radius there.
        assert!(close((Vec2::new(13.0, 0.0) - t).dot(t), 0.0));
        assert!(close(o.tip_angle(), 2.0 * (10.0f64 / 13.0).asin()));
        assert!(close(o.face, (169.0f64 - 100.0).sqrt()));
    }

    #[test]
    fn distances_to_the_arc_the_faces_and_the_tip_are_the_hand_computed_ones() {
        let o = wedge();
        // Behind: the round back.
        let (d, n) = o.distance(Vec2::new(-15.0, 0.0));
        assert!(close(d, 5.0) && n == Vec2::new(-1.0, 0.0), "{d} {n:?}");
        // Ahead of the tip.
        let (d, n) = o.distance(Vec2::new(16.0, 0.0));
        assert!(
            close(d, 3.0) && close(n.x, 1.0) && close(n.y, 0.0),
            "{d} {n:?}"
        );
        // Out from the middle of the right face, 2 along its normal.
        let t = o.tangent_point();
        let mid = (t + Vec2::new(13.0, 0.0)) * 0.5;
        let normal = t * 0.1;
        let (d, n) = o.distance(mid + normal * 2.0);
        assert!(close(d, 2.0) && close(n.x, normal.x) && close(n.y, normal.y));
        // The left face is its mirror image.
        let left = Vec2::new(mid.x, -mid.y) + Vec2::new(normal.x, -normal.y) * 2.0;
        let (d, n) = o.distance(left);
        assert!(close(d, 2.0) && close(n.y, -normal.y));
        // Inside, 1 behind the tip: nearest to either face, at 1 sin(half angle).
        let (d, _) = o.distance(Vec2::new(12.0, 0.0));
        assert!(close(d, -(o.tip_angle() / 2.0).sin()), "{d}");
        // The centre is a round back's radius deep.
        assert!(close(o.distance(Vec2::ZERO).0, -10.0));
    }

    #[test]
    fn a_circle_against_a_wedge_gives_the_general_hull_depth() {
        // A circle of radius rho against the wedge is the point delta in
        // the hull of two circles: r + rho at 0 and rho at the tip.
        let o = wedge();
        let mut rng = SimRng::seed_from_u64(5);
        for _ in 0..2000 {
            let delta = Vec2::new(rng.random_range(-30.0..30.0), rng.random_range(-30.0..30.0));
            let heading = rng.random_range(-3.2..3.2);
            let dir = Vec2::from_angle(heading);
            let rho = rng.random_range(1.0..12.0);
            let (depth, n) = o.circle_depth(dir, delta, rho);
            let (hull, m) = hull_depth(&[(Vec2::ZERO, 10.0 + rho), (dir * 13.0, rho)], delta);
            assert!(
                (depth - hull).abs() < 1e-9,
                "{delta:?} {heading}: {depth} {hull}"
            );
            if depth.abs() > 1e-6 {
                assert!((n - m).length() < 1e-6, "{delta:?}: {n:?} {m:?}");
            }
        }
    }

    #[test]
    fn a_hull_centred_on_its_first_circle_is_searched_to_the_same_bits() {
        let o = wedge();
        let mut rng = SimRng::seed_from_u64(9);
        for k in 0..4000 {
            let (a, b) = (
                Vec2::from_angle(rng.random_range(-3.2..3.2)) * o.tip(),
                Vec2::from_angle(rng.random_range(-3.2..3.2)) * o.tip(),
            );
            let r = o.radius();
            let circles = [(Vec2::ZERO, 2.0 * r), (a, r), (-b, r), (a - b, 0.0)];
            let delta = Vec2::new(rng.random_range(-40.0..40.0), rng.random_range(-40.0..40.0));
            let stop = if k % 2 == 0 { f64::NEG_INFINITY } else { 0.1 };
            let (d, n) = hull_depth_until(&circles, delta, stop, true);
            let (e, m) = hull_depth_until(&circles, delta, stop, false);
            assert_eq!(
                [d, n.x, n.y].map(f64::to_bits),
                [e, m.x, m.y].map(f64::to_bits),
                "{delta:?}"
            );
        }
    }

    #[test]
    fn the_hull_of_one_circle_is_that_circle() {
        let (d, n) = hull_depth(&[(Vec2::new(1.0, 1.0), 5.0)], Vec2::new(4.0, 5.0));
        assert!(
            close(d, 0.0) && close(n.x, 0.6) && close(n.y, 0.8),
            "{d} {n:?}"
        );
    }

    /// Whether the wedges of `pair_depth`'s arguments overlap, sampled:
    /// some point of `b`'s outline lies inside `a`'s.
    fn overlap_sampled(o: &Outline, dir_a: Vec2, dir_b: Vec2, delta: Vec2) -> bool {
        let right_b = Vec2::new(-dir_b.y, dir_b.x);
        let mut outline = vec![Vec2::new(13.0, 0.0)];
        outline.extend(
            (0..720).map(|k| Vec2::from_angle(k as f64 * std::f64::consts::TAU / 720.0) * 10.0),
        );
        outline.iter().any(|p| {
            let world = delta + dir_b * p.x + right_b * p.y;
            let right_a = Vec2::new(-dir_a.y, dir_a.x);
            o.distance(Vec2::new(world.dot(dir_a), world.dot(right_a)))
                .0
                < -1e-6
        })
    }

    #[test]
    fn a_depth_search_stops_only_at_or_below_its_bound_and_is_exact_above_it() {
        let o = wedge();
        let mut rng = SimRng::seed_from_u64(11);
        let mut stopped = 0;
        for _ in 0..2000 {
            let delta = Vec2::new(rng.random_range(-30.0..30.0), rng.random_range(-30.0..30.0));
            let (da, db) = (
                Vec2::from_angle(rng.random_range(-3.2..3.2)),
                Vec2::from_angle(rng.random_range(-3.2..3.2)),
            );
            let exact = o.pair_depth(da, db, delta);
            for stop in [-5.0, 0.0, 1e-9, 2.0] {
                let found = o.pair_depth_until(da, db, delta, stop);
                if exact.0 > stop {
                    assert_eq!(found, exact, "{delta:?} {stop}");
                } else {
                    assert!(found.0 <= stop, "{delta:?} {stop}");
                    stopped += usize::from(found != exact);
                }
            }
        }
        assert!(stopped > 1000, "{stopped}");
    }

    #[test]
    fn two_wedges_overlap_exactly_when_their_hull_depth_is_positive_and_separate_along_its_normal()
    {
        let o = wedge();
        let mut rng = SimRng::seed_from_u64(9);
        for _ in 0..400 {
            let delta = Vec2::new(rng.random_range(-30.0..30.0), rng.random_range(-30.0..30.0));
            let (da, db) = (
                Vec2::from_angle(rng.random_range(-3.2..3.2)),
                Vec2::from_angle(rng.random_range(-3.2..3.2)),
            );
            let (depth, n) = o.pair_depth(da, db, delta);
            if depth.abs() < 0.05 {
                continue; // too close to touching for the sampled test
            }
            assert_eq!(depth > 0.0, overlap_sampled(&o, da, db, delta), "{delta:?}");
            if depth > 0.0 {
                // Moved apart by the depth along n, they just touch.
                let (after, _) = o.pair_depth(da, db, delta + n * depth);
                assert!(after.abs() < 1e-9, "{after}");
                assert!(!overlap_sampled(&o, da, db, delta + n * (depth + 1e-3)));
            }
        }
    }
}
