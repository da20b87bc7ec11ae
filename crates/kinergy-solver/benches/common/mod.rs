//! What the solver benchmarks share: the arm's bones, and openrr `k`'s version of it with
//! revolute joints (k has no swing joints): shoulder X, Y, Z; elbow X, Z; wrist X, Y.

use kinergy_motion::rotation::Axis;

/// Upper arm, meters.
pub const UPPER: f64 = 0.30;
/// Forearm, meters.
pub const FORE: f64 = 0.26;
/// Hand, meters.
pub const HAND: f64 = 0.09;

/// The revolute axes of k's arm, in joint order.
pub const K_AXES: [Axis; 7] = [
    Axis::X,
    Axis::Y,
    Axis::Z,
    Axis::X,
    Axis::Z,
    Axis::X,
    Axis::Y,
];

/// k's 7-joint arm with the same bones along +z, with box `limits` per joint or none.
pub fn k_arm(limits: Option<&[(f64, f64); 7]>) -> k::SerialChain<f64> {
    use k::nalgebra as kn;
    let offsets = [0.0, 0.0, 0.0, UPPER, 0.0, FORE, 0.0];
    let mut nodes: Vec<k::Node<f64>> = (0..7)
        .map(|i| {
            let axis = match K_AXES[i] {
                Axis::X => kn::Vector3::x_axis(),
                Axis::Y => kn::Vector3::y_axis(),
                Axis::Z => kn::Vector3::z_axis(),
            };
            k::NodeBuilder::new()
                .name(&format!("j{i}"))
                .joint_type(k::JointType::Rotational { axis })
                .translation(kn::Translation3::new(0.0, 0.0, offsets[i]))
                .limits(limits.map(|l| k::joint::Range::new(l[i].0, l[i].1)))
                .into_node()
        })
        .collect();
    nodes.push(
        k::NodeBuilder::new()
            .name("hand")
            .joint_type(k::JointType::Fixed)
            .translation(kn::Translation3::new(0.0, 0.0, HAND))
            .into_node(),
    );
    for w in nodes.windows(2) {
        w[1].set_parent(&w[0]);
    }
    k::SerialChain::try_new(k::Chain::from_root(nodes[0].clone())).expect("serial")
}
