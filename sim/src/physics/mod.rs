//! One physics step of the reference model: robot velocities from their
//! headings, integration with deceleration, overlap resolution against the
//! walls and between circles in one canonical order, then elastic impulses.
//!
//! Canonical order: bodies take turns in ascending index. A body that is
//! awake (it moved this step or touched something last step) is checked
//! against the four walls (with [`Walls::Segments`]; with [`Walls::Clamp`]
//! the border only clamps), then against every other body in ascending
//! index, then clamped into the arena. A body that is asleep but was pushed
//! earlier in this step gets only the wall check and the clamp. Contacts are
//! recorded in that order and their impulses applied in it. The neighbour
//! index only narrows down which pairs are tested, so the grid and the
//! all-pairs search give bit-identical results.
//!
//! Robots' bodies are the disc of their radius or, with
//! [`crate::config::robot_shape::RobotShape::Wedge`], a round back with a
//! pointed wedge ([`outline`]): then a robot's contacts with pucks, other
//! robots and the walls take the outline's depth and normal where the discs
//! take the centre line, and follow the same rules (separation by mass
//! shares, the same elastic impulse along the normal, the walls as
//! stand-ins of the body's own mass). Contacts move bodies by translation
//! only; a robot's heading is its controller's alone.
//!
//! Room 4 of the simulator (`lib.rs`), the second stage of a step (world -> **physics** -> sensors -> control).

pub mod body;
pub(crate) mod broadphase;
pub mod grid;
pub mod outline;

use crate::base::bitset::BitSet;
use crate::base::rng::SimRng;
use crate::base::vec2::Vec2;
use crate::config::{PhysicsConfig, Walls};
use crate::physics::body::{Body, Robot};
use crate::physics::broadphase::{Candidates, NeighbourIndex};
use crate::physics::outline::Outline;
use rand::RngExt;

/// What the other side of a contact is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Contact {
    /// Two circles, by body index, in the order they were tested.
    Bodies(u32, u32),
    /// A circle and a wall. The wall acts as an immovable stand-in circle of
    /// the body's own mass at the closest wall point, moving at minus the
    /// body's velocity when the contact was found.
    Wall {
        /// The body.
        body: u32,
        /// Closest point of the wall segment.
        point: Vec2,
        /// The stand-in's velocity.
        velocity: Vec2,
    },
}

/// Per-step sets and buffers, reused so that stepping allocates nothing.
#[derive(Clone, Debug, Default)]
pub(crate) struct PhysicsScratch {
    /// Bodies that may move or touch something: robots, bodies with a
    /// velocity, bodies in contact last step (and, until the next step
    /// drops them, pucks that came to rest in the last one). Everything
    /// else is at rest and costs nothing.
    live: BitSet,
    /// Bodies checked against other bodies this step.
    awake: BitSet,
    /// Bodies still to take their turn: awake ones and those pushed by an
    /// earlier turn.
    pending: BitSet,
    /// Bodies whose position changed since [`PhysicsScratch::drain_moved`]
    /// last emptied the set (for incremental Eval).
    moved: BitSet,
    contacts: Vec<Contact>,
    candidates: Candidates,
    robot_pairs: Vec<(u32, u32)>,
}

impl PhysicsScratch {
    /// Buffers for `bodies`, of which the first `robots` are robots, with
    /// room for far more contacts than a step produces.
    pub fn new(bodies: &[Body], robots: usize) -> PhysicsScratch {
        let n = bodies.len();
        let mut live = BitSet::new(n);
        for (i, b) in bodies.iter().enumerate() {
            if i < robots || b.vel != Vec2::ZERO || b.in_contact {
                live.insert(i);
            }
        }
        PhysicsScratch {
            live,
            awake: BitSet::new(n),
            pending: BitSet::new(n),
            moved: BitSet::new(n),
            contacts: Vec::with_capacity(8 * n + 64),
            candidates: Candidates::new(n),
            robot_pairs: Vec::with_capacity(robots * robots / 2 + 1),
        }
    }

    /// The contacts recorded in the last step, in canonical order.
    pub fn contacts(&self) -> &[Contact] {
        &self.contacts
    }

    /// Distinct robot-robot pairs in contact in the last step.
    pub fn robot_contacts(&self) -> usize {
        self.robot_pairs.len()
    }

    /// Calls `f` for every body whose position changed since the last
    /// call, ascending, and empties the set.
    pub(crate) fn drain_moved(&mut self, mut f: impl FnMut(usize)) {
        let mut next = self.moved.next_from(0);
        while let Some(i) = next {
            next = self.moved.next_from(i + 1);
            f(i);
        }
        self.moved.clear();
    }
}

/// The arena, bodies and buffers one step works on.
pub(crate) struct StepContext<'a> {
    /// All bodies; robots first.
    pub bodies: &'a mut [Body],
    /// The robots (body `i` is robot `i`).
    pub robots: &'a [Robot],
    /// Robots' forward speed.
    pub forward_speed: f64,
    /// Each robot's forward speed this step, if not every robot drives at
    /// `forward_speed` (actuation noise).
    pub robot_speeds: Option<&'a [f64]>,
    /// Contact model.
    pub config: &'a PhysicsConfig,
    /// Arena width and height.
    pub arena: Vec2,
    /// The largest body radius.
    pub max_radius: f64,
    /// The robots' outline if they are wedges (`None`: discs).
    pub outline: Option<Outline>,
    /// Neighbour index, kept up to date with every move.
    pub index: &'a mut NeighbourIndex,
    /// Generator for the coincident-centre nudge.
    pub rng: &'a mut SimRng,
    /// Reused buffers.
    pub scratch: &'a mut PhysicsScratch,
}

/// The four walls of a `w` x `h` arena in the order contacts meet them:
/// (whether the wall is vertical, its coordinate, its inward normal).
#[inline]
fn walls(w: f64, h: f64) -> [(bool, f64, Vec2); 4] {
    [
        (false, 0.0, Vec2::new(0.0, 1.0)),
        (true, w, Vec2::new(-1.0, 0.0)),
        (false, h, Vec2::new(0.0, -1.0)),
        (true, 0.0, Vec2::new(1.0, 0.0)),
    ]
}

impl StepContext<'_> {
    /// Runs one step (dt = 1).
    pub fn step(&mut self) {
        self.integrate();
        self.resolve_overlaps();
        self.apply_impulses();
    }

    /// Velocity from heading for robots; rest below the stop speed; then
    /// `p += v`, `v -= k v`. Marks which bodies are awake. Only live bodies
    /// can move, so only they are visited; a puck that is neither moving
    /// nor in contact leaves the live set until a contact wakes it.
    fn integrate(&mut self) {
        let stop2 = self.config.stop_speed * self.config.stop_speed;
        let keep = 1.0 - self.config.deceleration;
        let robots = self.robots.len();
        let sc = &mut *self.scratch;
        sc.awake.clear();
        let mut next = sc.live.next_from(0);
        while let Some(i) = next {
            next = sc.live.next_from(i + 1);
            let b = &mut self.bodies[i];
            if i < robots {
                let speed = match self.robot_speeds {
                    Some(speeds) => speeds[i],
                    None => self.forward_speed,
                };
                b.vel = self.robots[i].direction * speed;
            }
            let moving = (b.vel.length_squared() >= stop2) & (b.vel != Vec2::ZERO);
            if moving {
                b.pos += b.vel;
                b.vel = b.vel * keep;
                self.index.moved(i, b.pos);
                sc.moved.insert(i);
            } else {
                b.vel = Vec2::ZERO;
            }
            if moving || b.in_contact {
                sc.awake.insert(i);
            } else if i >= robots {
                sc.live.remove(i);
            }
            b.in_contact = false;
        }
        sc.pending.copy_from(&sc.awake);
    }

    fn resolve_overlaps(&mut self) {
        self.scratch.contacts.clear();
        self.scratch.robot_pairs.clear();
        let mut cursor = 0;
        while let Some(i) = self.scratch.pending.next_from(cursor) {
            cursor = i + 1;
            if self.config.walls == Walls::Segments {
                match self.outline.filter(|_| i < self.robots.len()) {
                    None => self.resolve_walls(i),
                    Some(outline) => self.resolve_walls_outline(i, &outline),
                }
            }
            if self.scratch.awake.contains(i) {
                self.resolve_circles(i);
            }
            match self.outline.filter(|_| i < self.robots.len()) {
                None => self.clamp(i),
                Some(outline) => self.clamp_outline(i, &outline),
            }
        }
    }

    /// Records a contact between bodies `a` and `b`: both are in contact
    /// (and live), robot pairs are counted once per step.
    #[inline]
    fn record_bodies(&mut self, a: u32, b: u32) {
        for body in [a as usize, b as usize] {
            self.bodies[body].in_contact = true;
            self.scratch.live.insert(body);
        }
        let robots = self.robots.len() as u32;
        if a < robots && b < robots {
            let pair = (a.min(b), a.max(b));
            if !self.scratch.robot_pairs.contains(&pair) {
                self.scratch.robot_pairs.push(pair);
            }
        }
        self.scratch.contacts.push(Contact::Bodies(a, b));
    }

    /// Records a wall contact (rare: not inlined).
    #[inline(never)]
    fn record_wall(&mut self, body: u32, point: Vec2, velocity: Vec2) {
        self.bodies[body as usize].in_contact = true;
        self.scratch.live.insert(body as usize);
        self.scratch.contacts.push(Contact::Wall {
            body,
            point,
            velocity,
        });
    }

    /// The four border walls in a fixed order (top, right, bottom, left),
    /// each as a segment with the wall radius.
    fn resolve_walls(&mut self, i: usize) {
        let (w, h) = (self.arena.x, self.arena.y);
        let reach = self.bodies[i].radius + self.config.wall_radius - self.config.overlap_threshold;
        let p = self.bodies[i].pos;
        if (p.x >= reach) & (p.x <= w - reach) & (p.y >= reach) & (p.y <= h - reach) {
            return; // farther than `reach` from every wall: no contact possible
        }
        for (vertical, at, inward) in walls(w, h) {
            let b = self.bodies[i];
            let across = if vertical { b.pos.x - at } else { b.pos.y - at };
            if across.abs() >= reach {
                continue;
            }
            let point = if vertical {
                Vec2::new(at, b.pos.y.clamp(0.0, h))
            } else {
                Vec2::new(b.pos.x.clamp(0.0, w), at)
            };
            let delta = b.pos - point;
            let d = delta.length();
            let overlap = b.radius + self.config.wall_radius - d;
            if overlap <= self.config.overlap_threshold {
                continue;
            }
            let normal = if d > 0.0 { delta * (1.0 / d) } else { inward };
            self.bodies[i].pos += normal * overlap;
            self.relocated(i);
            self.record_wall(i as u32, point, -b.vel);
        }
    }

    /// The four walls against robot `i`'s outline, in the discs' order:
    /// the outline reaches `support` towards a wall, so it overlaps the
    /// wall by `support + wall_radius - across`, and is pushed out along
    /// the wall's inward normal. The stand-in sits where the discs' does,
    /// at the wall point nearest to the centre, so the impulse is along
    /// the same normal.
    fn resolve_walls_outline(&mut self, i: usize, outline: &Outline) {
        let (w, h) = (self.arena.x, self.arena.y);
        let reach = self.bodies[i].radius + self.config.wall_radius - self.config.overlap_threshold;
        let p = self.bodies[i].pos;
        if (p.x >= reach) & (p.x <= w - reach) & (p.y >= reach) & (p.y <= h - reach) {
            return;
        }
        let direction = self.robots[i].direction;
        for (vertical, at, inward) in walls(w, h) {
            let b = self.bodies[i];
            // The centre's distance from the wall, positive inside.
            let across = if vertical {
                (b.pos.x - at) * inward.x
            } else {
                (b.pos.y - at) * inward.y
            };
            let overlap = outline.support(direction, -inward) + self.config.wall_radius - across;
            if overlap <= self.config.overlap_threshold {
                continue;
            }
            let point = if vertical {
                Vec2::new(at, b.pos.y.clamp(0.0, h))
            } else {
                Vec2::new(b.pos.x.clamp(0.0, w), at)
            };
            self.bodies[i].pos += inward * overlap;
            self.relocated(i);
            self.record_wall(i as u32, point, -b.vel);
        }
    }

    /// Body `i` against every other body, ascending. Only bodies within a
    /// margin ([`CANDIDATE_MARGIN`]) of touching `i` are tested: the others
    /// cannot come to overlap unless `i` moves by more than the margin while
    /// being pushed (nothing else moves during `i`'s turn but the bodies it
    /// pushes, which are candidates), and then the candidates are gathered
    /// again. So the result is the all-pairs result, exactly.
    fn resolve_circles(&mut self, i: usize) {
        let margin = CANDIDATE_MARGIN * self.max_radius;
        let threshold = self.config.overlap_threshold;
        let candidates = &mut self.scratch.candidates;
        self.index.contact_candidates(
            self.bodies,
            i,
            None,
            self.max_radius,
            margin,
            threshold,
            candidates,
        );
        if candidates.as_slice().is_empty() {
            return;
        }
        let mut anchor = self.bodies[i].pos;
        let mut k = 0;
        while let Some(&j) = self.scratch.candidates.as_slice().get(k) {
            let j = j as usize;
            k += 1;
            if self.separate(i, j)
                && (self.bodies[i].pos - anchor).length_squared() > margin * margin
            {
                anchor = self.bodies[i].pos;
                let candidates = &mut self.scratch.candidates;
                self.index.contact_candidates(
                    self.bodies,
                    i,
                    Some(j),
                    self.max_radius,
                    margin,
                    threshold,
                    candidates,
                );
                k = 0;
            }
        }
    }

    /// Separates `i` and `j` if they overlap by more than the threshold,
    /// each by the overlap times the other's share of the mass, and records
    /// the contact. Returns whether they were separated.
    fn separate(&mut self, i: usize, j: usize) -> bool {
        let (ri, rj) = (self.bodies[i].radius, self.bodies[j].radius);
        let reach = ri + rj - self.config.overlap_threshold;
        let mut delta = self.bodies[j].pos - self.bodies[i].pos;
        let mut d2 = delta.length_squared();
        if (reach <= 0.0) | (d2 >= reach * reach) {
            return false;
        }
        if d2 == 0.0 {
            let nudge = Vec2::new(
                self.rng.random_range(-1.0..1.0),
                self.rng.random_range(-1.0..1.0),
            );
            self.bodies[j].pos += nudge;
            self.relocated(j);
            delta = self.bodies[j].pos - self.bodies[i].pos;
            d2 = delta.length_squared();
            if d2 == 0.0 {
                return false;
            }
        }
        if let Some(outline) = self.outline {
            if i.min(j) < self.robots.len() {
                return self.separate_outline(i, j, &outline);
            }
        }
        let d = d2.sqrt();
        self.push_apart(i, j, ri + rj - d, delta * (1.0 / d));
        true
    }

    /// Moves bodies `i` and `j`, overlapping by `overlap`, apart along the
    /// unit `normal` (from `i` to `j`) by shares of their masses, and
    /// records the contact.
    #[inline]
    fn push_apart(&mut self, i: usize, j: usize, overlap: f64, normal: Vec2) {
        let (mi, mj) = (self.bodies[i].mass, self.bodies[j].mass);
        let total = mi + mj;
        self.bodies[i].pos -= normal * (overlap * mj / total);
        self.bodies[j].pos += normal * (overlap * mi / total);
        self.relocated(i);
        self.relocated(j);
        self.scratch.pending.insert(j);
        self.record_bodies(i as u32, j as u32);
    }

    /// [`Self::separate`] for a pair with a wedge robot: the outline's
    /// depth and normal ([`StepContext::outline_contact`]) instead of the
    /// centre line's, the same shares of the overlap.
    fn separate_outline(&mut self, i: usize, j: usize, outline: &Outline) -> bool {
        let threshold = self.config.overlap_threshold;
        let (overlap, normal) = self.outline_contact(i, j, outline, threshold);
        if overlap <= threshold {
            return false;
        }
        self.push_apart(i, j, overlap, normal);
        true
    }

    /// How deep bodies `i` and `j` (one of them a robot) overlap and the
    /// unit normal along which `j` leaves `i`: wedge against wedge, or a
    /// wedge against a puck's circle. Two wedges' depth is only exact
    /// above `stop` ([`Outline::pair_depth_until`]).
    fn outline_contact(&self, i: usize, j: usize, outline: &Outline, stop: f64) -> (f64, Vec2) {
        let robots = self.robots.len();
        let delta = self.bodies[j].pos - self.bodies[i].pos;
        match (i < robots, j < robots) {
            (true, true) => outline.pair_depth_until(
                self.robots[i].direction,
                self.robots[j].direction,
                delta,
                stop,
            ),
            (true, false) => {
                outline.circle_depth(self.robots[i].direction, delta, self.bodies[j].radius)
            }
            _ => {
                let (depth, n) =
                    outline.circle_depth(self.robots[j].direction, -delta, self.bodies[i].radius);
                (depth, -n)
            }
        }
    }

    fn clamp(&mut self, i: usize) {
        let b = &mut self.bodies[i];
        let r = b.radius;
        let clamped = Vec2::new(
            b.pos.x.clamp(r, self.arena.x - r),
            b.pos.y.clamp(r, self.arena.y - r),
        );
        if clamped != b.pos {
            b.pos = clamped;
            self.relocated(i);
        }
    }

    /// [`Self::clamp`] for robot `i`'s outline: its reach along each axis
    /// kept within the arena.
    fn clamp_outline(&mut self, i: usize, outline: &Outline) {
        let d = self.robots[i].direction;
        let reach = |n: Vec2| outline.support(d, n);
        let b = &mut self.bodies[i];
        let clamped = Vec2::new(
            b.pos.x.clamp(
                reach(Vec2::new(-1.0, 0.0)),
                self.arena.x - reach(Vec2::new(1.0, 0.0)),
            ),
            b.pos.y.clamp(
                reach(Vec2::new(0.0, -1.0)),
                self.arena.y - reach(Vec2::new(0.0, 1.0)),
            ),
        );
        if clamped != b.pos {
            b.pos = clamped;
            self.relocated(i);
        }
    }

    /// Records that body `i`'s position changed during overlap resolution.
    #[inline]
    fn relocated(&mut self, i: usize) {
        self.index.moved(i, self.bodies[i].pos);
        self.scratch.moved.insert(i);
    }

    fn apply_impulses(&mut self) {
        let robots = self.robots.len();
        for c in &self.scratch.contacts {
            match *c {
                Contact::Bodies(a, b) => {
                    let (a, b) = (a as usize, b as usize);
                    let (mut x, mut y) = (self.bodies[a], self.bodies[b]);
                    match self.outline.filter(|_| a.min(b) < robots) {
                        None => elastic_impulse(&mut x, &mut y),
                        Some(outline) => {
                            // The contact's normal now, as the discs' centre line.
                            let (_, n) = self.outline_contact(a, b, &outline, f64::NEG_INFINITY);
                            impulse_along(&mut x, &mut y, n);
                        }
                    }
                    self.bodies[a].vel = x.vel;
                    self.bodies[b].vel = y.vel;
                }
                Contact::Wall {
                    body,
                    point,
                    velocity,
                } => {
                    let b = &mut self.bodies[body as usize];
                    let mut wall = Body {
                        pos: point,
                        vel: velocity,
                        ..*b
                    };
                    elastic_impulse(b, &mut wall);
                }
            }
        }
    }
}

/// The candidate margin as a fraction of the largest radius.
pub(crate) const CANDIDATE_MARGIN: f64 = 0.25;

/// The centre distance up to which a neighbour index must find contact
/// candidates: two largest radii plus the margin.
pub(crate) fn candidate_reach(max_radius: f64) -> f64 {
    (2.0 + CANDIDATE_MARGIN) * max_radius
}

/// The elastic collision of two circles along their centre line, with no
/// approach check: `v_a -= 2 m_b (n . (v_a - v_b)) / (m_a + m_b) n` and
/// the equal and opposite change of momentum for `b`. Coincident centres
/// exchange nothing.
pub fn elastic_impulse(a: &mut Body, b: &mut Body) {
    let delta = b.pos - a.pos;
    let d = delta.length();
    if d == 0.0 {
        return;
    }
    impulse_along(a, b, delta * (1.0 / d));
}

/// The elastic collision of two bodies along the unit normal `n` (from `a`
/// towards `b`): [`elastic_impulse`]'s exchange with the contact's normal
/// for the centre line.
#[inline]
pub fn impulse_along(a: &mut Body, b: &mut Body, n: Vec2) {
    let p = 2.0 * n.dot(a.vel - b.vel) / (a.mass + b.mass);
    a.vel -= n * (p * b.mass);
    b.vel += n * (p * a.mass);
}
