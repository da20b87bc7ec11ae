//! Finding a skeleton's limbs by joint role: the arm chain ([`ArmJoints`], clavicle →
//! shoulder → elbow → wrist → hand) and the leg ([`LegJoints`], hip → knee → ankle → toe).
//!
//! Names are split into lowercase tokens ([`name_tokens`]: at `_`, `:`, `.`, `-`, spaces and
//! camelCase boundaries; a `namespace:` prefix such as `mixamorig:` and Character Creator's
//! `CC_Base_` are dropped), a side token (`right`/`r`, `left`/`l`) is looked for, and the
//! remaining tokens, joined, give the role (`Shoulder_R` → `shoulder`, `CC_Base_L_Calf` →
//! `calf`). Each limb is found from its far end upward, skipping helper bones; [`arm`] and
//! [`leg`] list the names each role accepts; [`body`] puts the limbs, spine and head
//! together.

pub mod arm;
pub mod body;
pub mod leg;
mod names;

pub use arm::{ArmJoints, ArmLengths};
pub use body::BodyJoints;
pub use leg::LegJoints;
pub use names::{name_tokens, side_of};
