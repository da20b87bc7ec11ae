//! Serial kinematic chains for IK: joints made of revolute and swing motions, with joint
//! limits, forward kinematics and the positional Jacobian.
//!
//! The 7-DoF arm of Kallmann (2005) and Huang et al. is [`Chain::arm`]: shoulder swing (2) +
//! twist (1), elbow flexion (1) + twist (1), wrist swing (2). Each bone lies along its joint's
//! local +z; a swing is the rotation `exp([(sx, sy, 0)]×)` about an axis in the x–y plane, a
//! twist rotates about z (DESIGN §1.2–1.3).

use nalgebra::{IsometryMatrix3, Matrix3, Matrix3xX, Point3, Rotation3, Vector3};

use crate::error::{MotionError, Result};
use crate::rotation::{Axis, left_jacobian, swing_rotation_with, swing_with_jacobian_with};

/// One elementary motion of a chain joint.
#[derive(Debug, Clone, PartialEq)]
pub enum Motion {
    /// Rotation about a principal axis of the joint's frame; one DoF with limits `[min, max]`
    /// radians.
    Revolute {
        /// The axis.
        axis: Axis,
        /// Lower limit, radians.
        min: f64,
        /// Upper limit, radians.
        max: f64,
    },
    /// Swing: two DoFs `(sx, sy)`, the rotation `exp([(sx, sy, 0)]×)`, limited by the
    /// spherical ellipse `(sx/rx)² + (sy/ry)² ≤ 1` (Kallmann 2005, "Joint limits").
    Swing {
        /// Largest swing about x, radians.
        rx: f64,
        /// Largest swing about y, radians.
        ry: f64,
    },
}

impl Motion {
    /// DoFs of this motion: 1 or 2.
    pub fn dof_count(&self) -> usize {
        match self {
            Motion::Revolute { .. } => 1,
            Motion::Swing { .. } => 2,
        }
    }

    /// `r ← r · M(q)` at DoF values `q` (its first one or two). A principal-axis rotation
    /// changes only two columns of `r`: with (i, k) the axes after `a` cyclically,
    /// col_i ← c·col_i + s·col_k and col_k ← −s·col_i + c·col_k (12 multiplications instead of
    /// 27, the same values as the full product).
    #[inline]
    pub fn apply(&self, r: &mut Rotation3<f64>, q: &[f64]) {
        self.apply_with(r, q, crate::trig::sin_cos);
    }

    /// [`Motion::apply`] with the motion's angle's sine and cosine from `sin_cos(angle)` (a
    /// revolute's q, a swing's |v|; not called for a swing near zero): a memo of them gives
    /// the same bits.
    #[inline]
    pub(crate) fn apply_with(
        &self,
        r: &mut Rotation3<f64>,
        q: &[f64],
        sin_cos: impl FnOnce(f64) -> (f64, f64),
    ) {
        match *self {
            Motion::Revolute { axis, .. } => {
                let (s, c) = sin_cos(q[0]);
                let a = axis.index();
                let (i, k) = ((a + 1) % 3, (a + 2) % 3);
                let m = r.matrix_mut_unchecked();
                let ci = m.column(i).into_owned();
                let ck = m.column(k).into_owned();
                m.set_column(i, &(ci * c + ck * s));
                m.set_column(k, &(ck * c - ci * s));
            }
            Motion::Swing { .. } => *r *= swing_rotation_with(q[0], q[1], sin_cos),
        }
    }

    /// The bits of the DoF values that decide this motion's angle (a [`TrigMemo`]'s key).
    #[inline]
    fn key(&self, q: &[f64]) -> [u64; 2] {
        match self {
            Motion::Revolute { .. } => [q[0].to_bits(), 0],
            Motion::Swing { .. } => [q[0].to_bits(), q[1].to_bits()],
        }
    }

    /// The angle whose sine and cosine this motion's rotation takes at DoF values `q`: a
    /// revolute's q, a swing's |v| (computed as the swing's rotation computes it).
    #[inline]
    fn angle(&self, q: &[f64]) -> f64 {
        match self {
            Motion::Revolute { .. } => q[0],
            Motion::Swing { .. } => crate::rotation::swing_angle_squared(q[0], q[1]).sqrt(),
        }
    }
}

/// The sines and cosines of a chain's motions at the last configuration forward kinematics
/// walked, one per motion, keyed by the bits of its DoF values: a walk at a configuration
/// whose motion has bit-for-bit the same values takes them from here instead of calling
/// `sin_cos` again, so its results are the same to the bit. The synergy controller's frame
/// linearizes the chain at the configuration its smooth controller has just placed the hand
/// at ([`Chain::end_in_base_memo`], then [`Chain::linearize_memo_into`]): every `sin_cos`
/// of the linearization is found here.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TrigMemo {
    entries: Vec<Option<TrigEntry>>,
}

/// One motion's entry of a [`TrigMemo`]: the bits of its DoF values, its angle's sine and
/// cosine.
type TrigEntry = ([u64; 2], (f64, f64));

/// How many angles [`TrigMemo::fill`] computes at once.
const LANES: usize = 8;

impl TrigMemo {
    /// Enters every motion of `chain` at `q` (checked by the caller), their sines and cosines
    /// computed [`LANES`] at a time ([`crate::trig::sin_cos_lanes`]: the bits
    /// [`crate::trig::sin_cos`] gives one at a time, so a walk finds what it would have
    /// computed itself). All of them, entered already or not: a configuration whose hand is
    /// not known yet has moved every DoF the step moves, and looking the entries up first
    /// measured slower.
    fn fill(&mut self, chain: &Chain, q: &[f64]) {
        let mut angles = [0.0; LANES];
        let mut keys = [[0; 2]; LANES];
        let (mut n, mut first, mut k) = (0, 0, 0);
        for m in chain.joints.iter().flat_map(|j| &j.motions) {
            let values = &q[k..];
            k += m.dof_count();
            (angles[n], keys[n]) = (m.angle(values), m.key(values));
            n += 1;
            if n == LANES {
                self.enter(first, &angles, &keys[..n]);
                (first, n) = (first + n, 0);
            }
        }
        if n > 0 {
            self.enter(first, &angles, &keys[..n]);
        }
    }

    /// The sine and cosine [`TrigMemo::fill`] entered for motion `m`.
    #[inline]
    fn filled(&self, m: usize) -> (f64, f64) {
        self.entries[m].map_or((0.0, 1.0), |(_, sc)| sc)
    }

    /// Enters the sines and cosines of `angles` as the entries of motions `first…`, one per
    /// key of `keys` (the lanes beyond are not entered).
    fn enter(&mut self, first: usize, angles: &[f64; LANES], keys: &[[u64; 2]]) {
        let (s, c) = crate::trig::sin_cos_lanes(angles);
        if self.entries.len() < first + keys.len() {
            self.entries.resize(first + keys.len(), None);
        }
        for (i, (entry, &key)) in self.entries[first..].iter_mut().zip(keys).enumerate() {
            *entry = Some((key, (s[i], c[i])));
        }
    }

    /// The sine and cosine of motion `m`'s `angle`, whose DoF values have the bits `key`.
    #[inline]
    fn sin_cos(&mut self, m: usize, key: [u64; 2], angle: f64) -> (f64, f64) {
        if m >= self.entries.len() {
            self.entries.resize(m + 1, None);
        }
        match self.entries[m] {
            Some((k, sc)) if k == key => sc,
            _ => {
                let sc = crate::trig::sin_cos(angle);
                self.entries[m] = Some((key, sc));
                sc
            }
        }
    }
}

/// Where a walk of the chain takes its sines and cosines: `sin_cos` itself, or a [`TrigMemo`].
trait Trig {
    fn sin_cos(&mut self, m: usize, key: [u64; 2], angle: f64) -> (f64, f64);
}

/// The sines and cosines of one configuration's motions, computed at once in lanes before a
/// walk: the bits [`crate::trig::sin_cos`] gives one at a time (a chain of more than
/// [`LANES`] motions computes the others one at a time).
struct Batch {
    sin_cos: [(f64, f64); LANES],
    count: usize,
}

impl Batch {
    fn of(chain: &Chain, q: &[f64]) -> Batch {
        let mut angles = [0.0; LANES];
        let (mut count, mut k) = (0, 0);
        for m in chain.joints.iter().flat_map(|j| &j.motions).take(LANES) {
            angles[count] = m.angle(&q[k..]);
            k += m.dof_count();
            count += 1;
        }
        let (s, c) = crate::trig::sin_cos_lanes(&angles);
        Batch {
            sin_cos: std::array::from_fn(|i| (s[i], c[i])),
            count,
        }
    }
}

impl Trig for Batch {
    #[inline]
    fn sin_cos(&mut self, m: usize, _: [u64; 2], angle: f64) -> (f64, f64) {
        if m < self.count {
            self.sin_cos[m]
        } else {
            crate::trig::sin_cos(angle)
        }
    }
}

impl Trig for TrigMemo {
    #[inline]
    fn sin_cos(&mut self, m: usize, key: [u64; 2], angle: f64) -> (f64, f64) {
        TrigMemo::sin_cos(self, m, key, angle)
    }
}

/// One joint of a [`Chain`].
#[derive(Debug, Clone, PartialEq)]
pub struct ChainJoint {
    /// Name, used in DoF names (`shoulder` gives `shoulder_swing_x`, …).
    pub name: String,
    /// Position of this joint in the previous joint's frame (the base frame for the first).
    pub offset: Vector3<f64>,
    /// A fixed rotation applied before the joint's motions.
    pub rest: Rotation3<f64>,
    /// The motions, applied in order.
    pub motions: Vec<Motion>,
    /// The names of the motions' DoFs, one per DoF.
    pub dof_names: Vec<String>,
}

impl ChainJoint {
    /// A joint whose DoF names derive from its name and motions: a revolute about z is a
    /// `twist`, about x a `flexion`, about y an `abduction`; a swing gives `swing_x`, `swing_y`.
    pub fn new(name: &str, offset: Vector3<f64>, motions: Vec<Motion>) -> ChainJoint {
        let dof_names = motions
            .iter()
            .flat_map(|m| match m {
                Motion::Revolute { axis, .. } => vec![format!(
                    "{name}_{}",
                    match axis {
                        Axis::X => "flexion",
                        Axis::Y => "abduction",
                        Axis::Z => "twist",
                    }
                )],
                Motion::Swing { .. } => vec![format!("{name}_swing_x"), format!("{name}_swing_y")],
            })
            .collect();
        ChainJoint {
            name: name.to_string(),
            offset,
            rest: Rotation3::identity(),
            motions,
            dof_names,
        }
    }
}

/// A serial chain: joints from a base frame outward, and an end effector fixed in the last
/// joint's frame. Immutable; configurations are `&[f64]` of [`Chain::dof_count`] values.
#[derive(Debug, Clone, PartialEq)]
pub struct Chain {
    joints: Vec<ChainJoint>,
    /// Per joint: is `rest` the identity (skipped in the hot loops)?
    rest_identity: Vec<bool>,
    /// Per DoF: the index of its joint.
    dof_joint: Vec<usize>,
    end_effector: Vector3<f64>,
    dof_count: usize,
}

/// The end effector's pose and first-order kinematics at one configuration, filled by
/// [`Chain::linearize_into`] in a single pass (buffers reused between calls).
#[derive(Debug, Clone, PartialEq)]
pub struct Linearization {
    /// World position of each joint.
    pub joints: Vec<Point3<f64>>,
    /// World position of the end effector.
    pub end: Point3<f64>,
    /// World orientation of the last joint's frame (the end effector's orientation).
    pub end_rotation: Rotation3<f64>,
    /// `∂p_end/∂q`, 3 × DoFs, meters per radian.
    pub linear: Matrix3xX<f64>,
    /// World angular velocity of the end frame per unit `q̇`, 3 × DoFs.
    pub angular: Matrix3xX<f64>,
}

impl Default for Linearization {
    fn default() -> Linearization {
        Linearization {
            joints: Vec::new(),
            end: Point3::origin(),
            end_rotation: Rotation3::identity(),
            linear: Matrix3xX::zeros(0),
            angular: Matrix3xX::zeros(0),
        }
    }
}

/// The world frames of a chain's joints and its end effector in one configuration.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ChainPose {
    /// World frame of each joint after its motions.
    pub frames: Vec<IsometryMatrix3<f64>>,
    /// World position of the end effector.
    pub end: Point3<f64>,
}

impl ChainPose {
    /// World position of joint `i`.
    pub fn joint_position(&self, i: usize) -> Point3<f64> {
        Point3::from(self.frames[i].translation.vector)
    }
}

impl Chain {
    /// A chain from joints and the end effector's offset in the last joint's frame.
    pub fn new(joints: Vec<ChainJoint>, end_effector: Vector3<f64>) -> Result<Chain> {
        if joints.is_empty() {
            return Err(MotionError::Invalid {
                what: "chain",
                why: "it has no joints".into(),
            });
        }
        for j in &joints {
            let finite = j.offset.iter().all(|v| v.is_finite());
            let limits_ok = j.motions.iter().all(|m| match *m {
                Motion::Revolute { min, max, .. } => min <= max && !min.is_nan() && !max.is_nan(),
                Motion::Swing { rx, ry } => rx > 0.0 && ry > 0.0,
            });
            let names_ok =
                j.dof_names.len() == j.motions.iter().map(Motion::dof_count).sum::<usize>();
            if !(finite && limits_ok && names_ok) {
                return Err(MotionError::Invalid {
                    what: "chain joint",
                    why: format!(
                        "`{}` has a non-finite offset, inverted or non-positive limits, or a DoF name count that does not match its motions",
                        j.name
                    ),
                });
            }
        }
        if !end_effector.iter().all(|v| v.is_finite()) {
            return Err(MotionError::NonFinite {
                what: "the end effector offset".into(),
            });
        }
        let dof_count = joints
            .iter()
            .flat_map(|j| &j.motions)
            .map(Motion::dof_count)
            .sum();
        let dof_joint = joints
            .iter()
            .enumerate()
            .flat_map(|(i, j)| {
                std::iter::repeat_n(i, j.motions.iter().map(Motion::dof_count).sum())
            })
            .collect();
        Ok(Chain {
            dof_joint,
            rest_identity: joints
                .iter()
                .map(|j| j.rest == Rotation3::identity())
                .collect(),
            joints,
            end_effector,
            dof_count,
        })
    }

    /// The 7-DoF human arm with the given bone lengths (meters), straight along the base
    /// frame's +z at zero, with default limits: shoulder swing within an ellipse of 130°
    /// about x and 100° about y, twist ±90°; elbow flexion 0–150° (positive bends the forearm
    /// toward −y), pronation ±90°; wrist swing 70° about x and 30° about y.
    pub fn arm(upper_arm: f64, forearm: f64, hand: f64) -> Result<Chain> {
        let d = f64::to_radians;
        let rev = |axis, lo: f64, hi: f64| Motion::Revolute {
            axis,
            min: d(lo),
            max: d(hi),
        };
        Chain::new(
            vec![
                ChainJoint::new(
                    "shoulder",
                    Vector3::zeros(),
                    vec![
                        Motion::Swing {
                            rx: d(130.0),
                            ry: d(100.0),
                        },
                        rev(Axis::Z, -90.0, 90.0),
                    ],
                ),
                ChainJoint::new(
                    "elbow",
                    Vector3::new(0.0, 0.0, upper_arm),
                    vec![rev(Axis::X, 0.0, 150.0), rev(Axis::Z, -90.0, 90.0)],
                ),
                ChainJoint::new(
                    "wrist",
                    Vector3::new(0.0, 0.0, forearm),
                    vec![Motion::Swing {
                        rx: d(70.0),
                        ry: d(30.0),
                    }],
                ),
            ],
            Vector3::new(0.0, 0.0, hand),
        )
    }

    /// The joints.
    pub fn joints(&self) -> &[ChainJoint] {
        &self.joints
    }

    /// The end effector's offset in the last joint's frame.
    pub fn end_effector(&self) -> Vector3<f64> {
        self.end_effector
    }

    /// The number of DoFs.
    pub fn dof_count(&self) -> usize {
        self.dof_count
    }

    /// Every DoF's name, in configuration order.
    pub fn dof_names(&self) -> impl Iterator<Item = &str> + '_ {
        self.joints
            .iter()
            .flat_map(|j| j.dof_names.iter().map(String::as_str))
    }

    fn check(&self, q: &[f64]) -> Result<()> {
        if q.len() != self.dof_count {
            return Err(MotionError::PoseLength {
                expected: self.dof_count,
                found: q.len(),
            });
        }
        Ok(())
    }

    /// Forward kinematics from a world `base` frame into `out` (reused between calls).
    pub fn fk_into(
        &self,
        base: &IsometryMatrix3<f64>,
        q: &[f64],
        out: &mut ChainPose,
    ) -> Result<()> {
        self.check(q)?;
        out.frames.clear();
        out.end = self.walk(base, q, |frame| out.frames.push(*frame));
        Ok(())
    }

    /// Forward kinematics from `base` at `q` (checked): each joint's frame after its motions
    /// to `each`, in order; the end effector's position.
    #[inline]
    fn walk(
        &self,
        base: &IsometryMatrix3<f64>,
        q: &[f64],
        mut each: impl FnMut(&IsometryMatrix3<f64>),
    ) -> Point3<f64> {
        let mut frame = *base;
        let mut k = 0;
        for (j, &rest_identity) in self.joints.iter().zip(&self.rest_identity) {
            self.enter_joint(&mut frame, j, rest_identity);
            for m in &j.motions {
                apply_motion(&mut frame.rotation, m, &q[k..]);
                k += m.dof_count();
            }
            each(&frame);
        }
        frame * Point3::from(self.end_effector)
    }

    /// Moves `frame` from the previous joint to joint `j`, before its motions.
    #[inline]
    fn enter_joint(&self, frame: &mut IsometryMatrix3<f64>, j: &ChainJoint, rest_identity: bool) {
        frame.translation.vector += frame.rotation * j.offset;
        if !rest_identity {
            frame.rotation *= j.rest;
        }
    }

    /// Forward kinematics from a world `base` frame.
    pub fn fk(&self, base: &IsometryMatrix3<f64>, q: &[f64]) -> Result<ChainPose> {
        let mut out = ChainPose {
            frames: Vec::with_capacity(self.joints.len()),
            end: Point3::origin(),
        };
        self.fk_into(base, q, &mut out)?;
        Ok(out)
    }

    /// World position of the end effector: [`Chain::fk`]'s `end`, without the joint frames
    /// (no allocation; the same arithmetic, so the same bits).
    pub fn end_position(&self, base: &IsometryMatrix3<f64>, q: &[f64]) -> Result<Point3<f64>> {
        self.check(q)?;
        Ok(self.walk(base, q, |_| {}))
    }

    /// The end effector's position in the chain's base frame at `q` (checked), computed from
    /// the end inward: each joint's motions turn the point as it stands in their frame, then
    /// the joint's rest rotation and offset carry it into the parent's. A rotation applied to
    /// a point instead of a product of rotations: about a third of [`Chain::end_position`]'s
    /// multiplications, the same position within rounding (not the same bits: the products
    /// associate otherwise). The sines and cosines of all the motions are computed at once,
    /// in lanes ([`crate::trig::sin_cos_lanes`]), and kept in `memo` for a linearization at
    /// the same configuration ([`Chain::linearize_memo_into`]).
    pub fn end_in_base_memo(&self, q: &[f64], memo: &mut TrigMemo) -> Result<Point3<f64>> {
        self.check(q)?;
        memo.fill(self, q);
        let mut v = self.end_effector;
        let mut k = self.dof_count;
        let mut index = self.joints.iter().map(|j| j.motions.len()).sum::<usize>();
        for (j, &rest_identity) in self.joints.iter().zip(&self.rest_identity).rev() {
            for m in j.motions.iter().rev() {
                k -= m.dof_count();
                index -= 1;
                let q = &q[k..];
                match *m {
                    Motion::Revolute { axis, .. } => {
                        let (s, c) = memo.filled(index);
                        let a = axis.index();
                        let (i, l) = ((a + 1) % 3, (a + 2) % 3);
                        let (vi, vl) = (v[i], v[l]);
                        v[i] = c * vi - s * vl;
                        v[l] = s * vi + c * vl;
                    }
                    Motion::Swing { .. } => {
                        let r = swing_rotation_with(q[0], q[1], |_| memo.filled(index));
                        v = r * v;
                    }
                }
            }
            if !rest_identity {
                v = j.rest * v;
            }
            v += j.offset;
        }
        Ok(Point3::from(v))
    }

    /// The positional Jacobian (3 × DoFs) of the end effector at `q`, into `out`.
    ///
    /// A revolute DoF about world axis ω through joint origin p_i gives ω × (p_e − p_i); a
    /// swing `v = (sx, sy, 0)` whose frame before the swing has world rotation R gives the
    /// columns (R J_l(v) e_x) × (p_e − p_i) and (R J_l(v) e_y) × (p_e − p_i), with J_l the
    /// left Jacobian of SO(3) ([`crate::rotation::left_jacobian`]).
    pub fn jacobian_into(
        &self,
        base: &IsometryMatrix3<f64>,
        q: &[f64],
        out: &mut Matrix3xX<f64>,
    ) -> Result<()> {
        self.check(q)?;
        if out.ncols() != self.dof_count {
            *out = Matrix3xX::zeros(self.dof_count);
        }
        // One pass to find the end effector, one to fill columns.
        let end = self.end_position(base, q)?.coords;
        let mut frame = *base;
        let mut k = 0;
        for (j, &rest_identity) in self.joints.iter().zip(&self.rest_identity) {
            self.enter_joint(&mut frame, j, rest_identity);
            let r = frame.translation.vector;
            let lever = end - r;
            for m in &j.motions {
                let rot: Matrix3<f64> = *frame.rotation.matrix();
                match *m {
                    Motion::Revolute { axis, .. } => {
                        let w = rot.column(axis.index()).into_owned();
                        out.set_column(k, &w.cross(&lever));
                    }
                    Motion::Swing { .. } => {
                        let jl = rot * left_jacobian(&Vector3::new(q[k], q[k + 1], 0.0));
                        out.set_column(k, &jl.column(0).cross(&lever));
                        out.set_column(k + 1, &jl.column(1).cross(&lever));
                    }
                }
                apply_motion(&mut frame.rotation, m, &q[k..]);
                k += m.dof_count();
            }
        }
        Ok(())
    }

    /// Forward kinematics and both Jacobians in one pass, sharing the trigonometry: the
    /// solvers' per-frame call. Column k of `angular` is DoF k's world rotation axis ω_k
    /// (for a swing, the rotated left-Jacobian column), column k of `linear` is
    /// ω_k × (p_end − p_joint(k)).
    pub fn linearize_into(
        &self,
        base: &IsometryMatrix3<f64>,
        q: &[f64],
        out: &mut Linearization,
    ) -> Result<()> {
        self.check(q)?;
        self.linearize_with(base, q, out, &mut Batch::of(self, q))
    }

    /// [`Chain::linearize_into`] with the sines and cosines kept in `memo` (and taken from
    /// it where a motion's DoF values are the last walk's, bit for bit): the same bits.
    pub fn linearize_memo_into(
        &self,
        base: &IsometryMatrix3<f64>,
        q: &[f64],
        out: &mut Linearization,
        memo: &mut TrigMemo,
    ) -> Result<()> {
        self.check(q)?;
        self.linearize_with(base, q, out, memo)
    }

    /// [`Chain::linearize_into`] with the sines and cosines from `trig` (`q` checked by the
    /// caller).
    fn linearize_with(
        &self,
        base: &IsometryMatrix3<f64>,
        q: &[f64],
        out: &mut Linearization,
        trig: &mut impl Trig,
    ) -> Result<()> {
        if out.linear.ncols() != self.dof_count {
            out.linear = Matrix3xX::zeros(self.dof_count);
            out.angular = Matrix3xX::zeros(self.dof_count);
        }
        out.joints.clear();
        let mut frame = *base;
        let (mut k, mut index) = (0, 0);
        for (j, &rest_identity) in self.joints.iter().zip(&self.rest_identity) {
            self.enter_joint(&mut frame, j, rest_identity);
            out.joints.push(Point3::from(frame.translation.vector));
            for m in &j.motions {
                let key = m.key(&q[k..]);
                let sin_cos = |angle: f64| trig.sin_cos(index, key, angle);
                match *m {
                    Motion::Revolute { axis, .. } => {
                        let rot = frame.rotation.matrix();
                        out.angular.set_column(k, &rot.column(axis.index()));
                        m.apply_with(&mut frame.rotation, &q[k..], sin_cos);
                    }
                    Motion::Swing { .. } => {
                        let (s, jx, jy) = swing_with_jacobian_with(q[k], q[k + 1], sin_cos);
                        let rot = *frame.rotation.matrix();
                        out.angular.set_column(k, &(rot * jx));
                        out.angular.set_column(k + 1, &(rot * jy));
                        frame.rotation = Rotation3::from_matrix_unchecked(rot * s);
                    }
                }
                k += m.dof_count();
                index += 1;
            }
        }
        out.end = frame * Point3::from(self.end_effector);
        out.end_rotation = frame.rotation;
        for (c, &j) in self.dof_joint.iter().enumerate() {
            let lever = out.end - out.joints[j];
            let w = out.angular.column(c).into_owned();
            out.linear.set_column(c, &w.cross(&lever));
        }
        Ok(())
    }

    /// The positional Jacobian of the end effector at `q`.
    pub fn jacobian(&self, base: &IsometryMatrix3<f64>, q: &[f64]) -> Result<Matrix3xX<f64>> {
        let mut j = Matrix3xX::zeros(self.dof_count);
        self.jacobian_into(base, q, &mut j)?;
        Ok(j)
    }

    /// True when every DoF of `q` is within its limits (swings inside their ellipse).
    pub fn within_limits(&self, q: &[f64]) -> bool {
        let mut k = 0;
        self.joints.iter().flat_map(|j| &j.motions).all(|m| {
            let ok = match *m {
                Motion::Revolute { min, max, .. } => (min..=max).contains(&q[k]),
                Motion::Swing { rx, ry } => {
                    (q[k] / rx).powi(2) + (q[k + 1] / ry).powi(2) <= 1.0 + 1e-12
                }
            };
            k += m.dof_count();
            ok
        })
    }

    /// The DoFs of `q` lying on their limit (within `tol` radians; for a swing, both DoFs
    /// when it lies within `tol` of its ellipse, measured on the normalized ellipse value).
    pub fn dofs_at_limits(&self, q: &[f64], tol: f64) -> Vec<usize> {
        let mut out = Vec::new();
        let mut k = 0;
        for m in self.joints.iter().flat_map(|j| &j.motions) {
            match *m {
                Motion::Revolute { min, max, .. } => {
                    if q[k] <= min + tol || q[k] >= max - tol {
                        out.push(k);
                    }
                }
                Motion::Swing { rx, ry } => {
                    let e = ((q[k] / rx).powi(2) + (q[k + 1] / ry).powi(2)).sqrt();
                    if e >= 1.0 - tol {
                        out.extend([k, k + 1]);
                    }
                }
            }
            k += m.dof_count();
        }
        out
    }

    /// Brings `q` within the limits: revolute DoFs are clamped; a swing outside its ellipse
    /// is scaled toward zero onto the ellipse (keeping the swing axis's direction).
    pub fn clamp(&self, q: &mut [f64]) {
        let mut k = 0;
        for m in self.joints.iter().flat_map(|j| &j.motions) {
            match *m {
                Motion::Revolute { min, max, .. } => q[k] = q[k].clamp(min, max),
                Motion::Swing { rx, ry } => {
                    let e = (q[k] / rx).powi(2) + (q[k + 1] / ry).powi(2);
                    if e > 1.0 {
                        let s = 1.0 / e.sqrt();
                        q[k] *= s;
                        q[k + 1] *= s;
                    }
                }
            }
            k += m.dof_count();
        }
    }
}

/// `r ← r · M(q)` ([`Motion::apply`]).
#[inline]
fn apply_motion(r: &mut Rotation3<f64>, m: &Motion, q: &[f64]) {
    m.apply(r, q);
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::{Translation3, UnitQuaternion};
    use proptest::prelude::*;

    fn base() -> IsometryMatrix3<f64> {
        IsometryMatrix3::from_parts(
            Translation3::new(0.2, 1.4, -0.1),
            UnitQuaternion::from_euler_angles(0.3, -1.2, 0.5).to_rotation_matrix(),
        )
    }

    #[test]
    fn straight_arm_reaches_full_length_along_base_z() {
        let arm = Chain::arm(0.3, 0.25, 0.08).expect("arm");
        assert_eq!(arm.dof_count(), 7);
        let end = arm.end_position(&base(), &[0.0; 7]).expect("fk");
        let expected = base() * Point3::new(0.0, 0.0, 0.63);
        assert_relative_eq!(end, expected, epsilon = 1e-12);
        let names: Vec<_> = arm.dof_names().collect();
        assert_eq!(
            names,
            [
                "shoulder_swing_x",
                "shoulder_swing_y",
                "shoulder_twist",
                "elbow_flexion",
                "elbow_twist",
                "wrist_swing_x",
                "wrist_swing_y"
            ]
        );
    }

    #[test]
    fn elbow_flexion_closes_the_arm_by_the_law_of_cosines() {
        let arm = Chain::arm(0.3, 0.25, 0.0).expect("arm");
        let flex = 1.1;
        let q = [0.0, 0.0, 0.0, flex, 0.0, 0.0, 0.0];
        let end = arm
            .end_position(&IsometryMatrix3::identity(), &q)
            .expect("fk");
        let expected = (0.3f64.powi(2) + 0.25f64.powi(2) + 2.0 * 0.3 * 0.25 * flex.cos()).sqrt();
        assert_relative_eq!(end.coords.norm(), expected, epsilon = 1e-12);
        assert!(end.y < 0.0, "positive flexion bends toward -y");
    }

    #[test]
    fn clamp_lands_inside_limits() {
        let arm = Chain::arm(0.3, 0.25, 0.08).expect("arm");
        let mut q = [3.0, -3.0, 2.0, -1.0, 5.0, 2.0, 2.0];
        assert!(!arm.within_limits(&q));
        arm.clamp(&mut q);
        assert!(arm.within_limits(&q));
        assert_relative_eq!(q[3], 0.0);
    }

    proptest! {
        /// A memo of the sines and cosines changes no bit: walks at new configurations, at
        /// the same one again, at one differing in a single DoF (the other motions' entries
        /// reused), with the swings near zero (the series, no `sin_cos`) and exactly zero.
        /// The memo's entries are the hand's sines and cosines computed in lanes, and a
        /// missing one is computed alone; the plain walk's are all in lanes.
        #[test]
        fn a_trig_memo_gives_the_plain_walks_bits(
            walks in proptest::collection::vec(
                (proptest::collection::vec(-2.0f64..2.0, 7), 0usize..7, -2.0f64..2.0, 0u8..4),
                1..12,
            ),
        ) {
            let arm = Chain::arm(0.31, 0.27, 0.09).expect("arm");
            let b = base();
            let mut memo = TrigMemo::default();
            let (mut plain, mut memoized) = (Linearization::default(), Linearization::default());
            let mut previous: Option<Vec<f64>> = None;
            for (fresh, dof, value, how) in walks {
                let mut q = match (how, &previous) {
                    // The last configuration again, or with one DoF moved.
                    (0, Some(p)) => p.clone(),
                    (1, Some(p)) => {
                        let mut q = p.clone();
                        q[dof] = value;
                        q
                    }
                    _ => fresh,
                };
                if how == 2 {
                    // Swings near zero, and at zero.
                    (q[0], q[1], q[5], q[6]) = (1e-7 * value, 0.0, 0.0, -0.0);
                }
                // The smooth controller's order: the hand, then the linearization.
                let inward = arm.end_in_base_memo(&q, &mut memo).expect("end");
                let alone = arm.end_in_base_memo(&q, &mut TrigMemo::default()).expect("end");
                prop_assert_eq!(inward.coords.map(f64::to_bits), alone.coords.map(f64::to_bits));
                arm.linearize_into(&b, &q, &mut plain).expect("linearize");
                arm.linearize_memo_into(&b, &q, &mut memoized, &mut memo).expect("linearize");
                let bits = |l: &Linearization| {
                    let mut v: Vec<u64> = l.linear.iter().chain(l.angular.iter()).map(|x| x.to_bits()).collect();
                    v.extend(l.end.coords.iter().map(|x| x.to_bits()));
                    v.extend(l.end_rotation.matrix().iter().map(|x| x.to_bits()));
                    v.extend(l.joints.iter().flat_map(|p| p.coords.iter().map(|x| x.to_bits())));
                    v
                };
                prop_assert_eq!(bits(&plain), bits(&memoized));
                previous = Some(q);
            }
        }

        #[test]
        fn the_end_from_the_hand_inward_is_the_end_within_rounding(
            q in proptest::collection::vec(-2.0f64..2.0, 7),
            near_zero in proptest::bool::ANY,
        ) {
            let mut q = q;
            if near_zero {
                // Swings at and near zero (the series).
                (q[0], q[1], q[5], q[6]) = (1e-7 * q[2], 0.0, 0.0, -0.0);
            }
            let mut arm = Chain::arm(0.31, 0.27, 0.09).expect("arm");
            // A rest rotation on the elbow too (a capture's chain has them).
            let mut joints = arm.joints().to_vec();
            joints[1].rest = crate::rotation::axis_rotation(Axis::Y, 0.4);
            for chain in [arm.clone(), Chain::new(joints, arm.end_effector()).expect("chain")] {
                let expected = chain.end_position(&IsometryMatrix3::identity(), &q).expect("end");
                let mut memo = TrigMemo::default();
                let inward = chain.end_in_base_memo(&q, &mut memo).expect("end");
                prop_assert!((inward - expected).norm() < 1e-15, "{} m apart", (inward - expected).norm());
                // Again from the memo: the same bits.
                let again = chain.end_in_base_memo(&q, &mut memo).expect("end");
                prop_assert_eq!(again.coords.map(f64::to_bits), inward.coords.map(f64::to_bits));
            }
            arm = Chain::arm(0.5, 0.4, 0.1).expect("arm");
            prop_assert!(arm.end_in_base_memo(&q[..6], &mut TrigMemo::default()).is_err());
        }

        #[test]
        fn end_position_is_fks_end_and_a_principal_axis_motion_its_full_product(
            q in proptest::collection::vec(-2.0f64..2.0, 7),
            angle in -4.0f64..4.0,
        ) {
            let arm = Chain::arm(0.31, 0.27, 0.09).expect("arm");
            let b = base();
            // The same arithmetic, so the same bits.
            assert_eq!(arm.end_position(&b, &q).expect("end"), arm.fk(&b, &q).expect("fk").end);
            for axis in [Axis::X, Axis::Y, Axis::Z] {
                let m = Motion::Revolute { axis, min: -4.0, max: 4.0 };
                let mut r = b.rotation;
                m.apply(&mut r, &[angle]);
                let full = b.rotation * crate::rotation::axis_rotation(axis, angle);
                assert_relative_eq!(r, full, epsilon = 1e-15);
            }
        }

        #[test]
        fn linearization_matches_fk_jacobian_and_finite_differences(q in proptest::collection::vec(-2.0f64..2.0, 7)) {
            let arm = Chain::arm(0.31, 0.27, 0.09).expect("arm");
            let b = base();
            let mut lin = Linearization::default();
            arm.linearize_into(&b, &q, &mut lin).expect("linearize");
            let pose = arm.fk(&b, &q).expect("fk");
            assert_relative_eq!(lin.end, pose.end, epsilon = 1e-12);
            assert_relative_eq!(lin.end_rotation, pose.frames[2].rotation, epsilon = 1e-12);
            for (i, p) in lin.joints.iter().enumerate() {
                assert_relative_eq!(*p, pose.joint_position(i), epsilon = 1e-12);
            }
            assert_relative_eq!(lin.linear, arm.jacobian(&b, &q).expect("jacobian"), epsilon = 1e-12);
            // Angular columns: (R(q + h e_d) − R(q − h e_d)) / 2h · Rᵀ = [ω_d]×.
            let h = 1e-6;
            for d in 0..7 {
                let mut plus = q.clone();
                let mut minus = q.clone();
                plus[d] += h;
                minus[d] -= h;
                let rp = arm.fk(&b, &plus).expect("fk").frames[2].rotation;
                let rm = arm.fk(&b, &minus).expect("fk").frames[2].rotation;
                let w = (rp.matrix() - rm.matrix()) / (2.0 * h) * pose.frames[2].rotation.matrix().transpose();
                let omega = Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
                assert_relative_eq!(lin.angular.column(d).into_owned(), omega, epsilon = 1e-7);
            }
        }

        #[test]
        fn jacobian_matches_finite_differences(q in proptest::collection::vec(-2.0f64..2.0, 7)) {
            let arm = Chain::arm(0.31, 0.27, 0.09).expect("arm");
            let b = base();
            let jac = arm.jacobian(&b, &q).expect("jacobian");
            let h = 1e-6;
            for d in 0..7 {
                let mut plus = q.clone();
                let mut minus = q.clone();
                plus[d] += h;
                minus[d] -= h;
                let fd = (arm.end_position(&b, &plus).expect("fk") - arm.end_position(&b, &minus).expect("fk")) / (2.0 * h);
                assert_relative_eq!(jac.column(d).into_owned(), fd, epsilon = 1e-7);
            }
        }
    }
}
