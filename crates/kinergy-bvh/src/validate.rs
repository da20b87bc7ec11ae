//! Consistency of an in-memory document: what the writer needs so that the file it
//! writes reads back as the same document.

use crate::document::{Bvh, is_valid_name};
use crate::error::WriteError;
use crate::read::MAX_DEPTH;

impl Bvh {
    /// Checks that the document can be written and read back unchanged:
    ///
    /// * there is at least one joint; joint 0 is the root (no parent, not an End Site) and
    ///   no other joint lacks a parent;
    /// * every parent comes before its children, in depth-first order (the parent of joint
    ///   `i` is joint `i - 1` or one of its ancestors), nested at most
    ///   [`MAX_DEPTH`] deep;
    /// * every joint's `first_channel` is the number of channels of the joints before it,
    ///   and no joint lists a channel twice;
    /// * `motion.len() == frame_count * channel_count()`;
    /// * offsets and motion values are finite, and `frame_time` is within
    ///   [`MIN_FRAME_TIME`](crate::MIN_FRAME_TIME)..=[`MAX_FRAME_TIME`](crate::MAX_FRAME_TIME);
    /// * joint names are non-empty, not `{` or `}`, and without whitespace or control
    ///   characters; End Sites have no name, no channels and no children.
    ///
    /// Every document [`parse`](crate::parse) returns passes. Returns the first problem.
    pub fn validate(&self) -> Result<(), WriteError> {
        let Some(root) = self.joints.first() else {
            return Err(WriteError::NoJoints);
        };
        if root.parent.is_some() || root.end_site {
            return Err(WriteError::RootNotFirst);
        }

        // The ancestors of the joint before the current one, root first.
        let mut path: Vec<usize> = Vec::new();
        let mut channels = 0usize;
        for (index, joint) in self.joints.iter().enumerate() {
            if index > 0 {
                let Some(parent) = joint.parent else {
                    return Err(WriteError::MultipleRoots { joint: index });
                };
                if parent >= index {
                    return Err(WriteError::ParentAfterChild {
                        joint: index,
                        parent,
                    });
                }
                while path.last().is_some_and(|&p| p != parent) {
                    path.pop();
                }
                if path.is_empty() {
                    return Err(WriteError::NotDepthFirst { joint: index });
                }
                if self.joints.get(parent).is_some_and(|p| p.end_site) {
                    return Err(WriteError::EndSiteChildren { joint: parent });
                }
            }
            path.push(index);
            if path.len() > MAX_DEPTH {
                return Err(WriteError::TooDeep {
                    joint: index,
                    max: MAX_DEPTH,
                });
            }

            match (&joint.name, joint.end_site) {
                (Some(_), true) => return Err(WriteError::EndSiteName { joint: index }),
                (None, false) => return Err(WriteError::MissingName { joint: index }),
                (Some(name), false) if !is_valid_name(name) => {
                    return Err(WriteError::InvalidName {
                        joint: index,
                        name: name.clone(),
                    });
                }
                _ => {}
            }
            if joint.end_site && !joint.channels.is_empty() {
                return Err(WriteError::EndSiteChannels { joint: index });
            }
            for (k, channel) in joint.channels.iter().enumerate() {
                if joint
                    .channels
                    .get(..k)
                    .is_some_and(|before| before.contains(channel))
                {
                    return Err(WriteError::DuplicateChannel {
                        joint: index,
                        channel: *channel,
                    });
                }
            }
            if joint.first_channel != channels {
                return Err(WriteError::ChannelOffset {
                    joint: index,
                    expected: channels,
                    found: joint.first_channel,
                });
            }
            channels = channels.saturating_add(joint.channels.len());
            if !joint.offset.iter().all(|v| v.is_finite()) {
                return Err(WriteError::NonFiniteOffset { joint: index });
            }
        }

        if Some(self.motion.len()) != self.frame_count.checked_mul(channels) {
            return Err(WriteError::MotionLength {
                frame_count: self.frame_count,
                channel_count: channels,
                values: self.motion.len(),
            });
        }
        if let Some(bad) = self.motion.iter().position(|v| !v.is_finite()) {
            return Err(WriteError::NonFiniteMotion {
                frame: bad.checked_div(channels).unwrap_or(0),
                channel: bad.checked_rem(channels).unwrap_or(0),
            });
        }
        if !(crate::MIN_FRAME_TIME..=crate::MAX_FRAME_TIME).contains(&self.frame_time) {
            return Err(WriteError::BadFrameTime {
                value: self.frame_time,
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::{Bvh, Channel, Joint, WriteError};

    fn joint(
        name: Option<&str>,
        parent: Option<usize>,
        channels: &[Channel],
        first: usize,
    ) -> Joint {
        Joint {
            name: name.map(str::to_owned),
            parent,
            offset: [0.0; 3],
            channels: channels.to_vec(),
            first_channel: first,
            end_site: name.is_none(),
            line: 0,
        }
    }

    fn small() -> Bvh {
        Bvh {
            joints: vec![
                joint(
                    Some("Hips"),
                    None,
                    &[Channel::Xposition, Channel::Zrotation],
                    0,
                ),
                joint(Some("Spine"), Some(0), &[Channel::Yrotation], 2),
                joint(None, Some(1), &[], 3),
                joint(Some("Leg"), Some(0), &[Channel::Xrotation], 3),
            ],
            frame_time: 0.5,
            frame_count: 2,
            motion: vec![0.0; 8],
        }
    }

    #[test]
    fn a_consistent_document_passes() {
        assert_eq!(small().validate(), Ok(()));
    }

    #[test]
    fn each_inconsistency_is_named() {
        type Case = (fn(&mut Bvh), WriteError);
        let cases: Vec<Case> = vec![
            (|b| b.joints.clear(), WriteError::NoJoints),
            (|b| b.joints[0].parent = Some(0), WriteError::RootNotFirst),
            (
                |b| b.joints[3].parent = None,
                WriteError::MultipleRoots { joint: 3 },
            ),
            (
                |b| b.joints[1].parent = Some(1),
                WriteError::ParentAfterChild {
                    joint: 1,
                    parent: 1,
                },
            ),
            (
                |b| b.joints.push(joint(Some("Arm"), Some(1), &[], 4)),
                WriteError::NotDepthFirst { joint: 4 },
            ),
            (
                |b| b.joints[3].parent = Some(2),
                WriteError::EndSiteChildren { joint: 2 },
            ),
            (
                |b| b.joints[2].channels = vec![Channel::Xrotation],
                WriteError::EndSiteChannels { joint: 2 },
            ),
            (
                |b| b.joints[2].name = Some("x".into()),
                WriteError::EndSiteName { joint: 2 },
            ),
            (
                |b| b.joints[1].name = None,
                WriteError::MissingName { joint: 1 },
            ),
            (
                |b| b.joints[1].name = Some("Left Arm".into()),
                WriteError::InvalidName {
                    joint: 1,
                    name: "Left Arm".into(),
                },
            ),
            (
                |b| b.joints[1].name = Some(String::new()),
                WriteError::InvalidName {
                    joint: 1,
                    name: String::new(),
                },
            ),
            (
                |b| b.joints[1].name = Some("{".into()),
                WriteError::InvalidName {
                    joint: 1,
                    name: "{".into(),
                },
            ),
            (
                |b| b.joints[0].channels[1] = Channel::Xposition,
                WriteError::DuplicateChannel {
                    joint: 0,
                    channel: Channel::Xposition,
                },
            ),
            (
                |b| b.joints[3].first_channel = 2,
                WriteError::ChannelOffset {
                    joint: 3,
                    expected: 3,
                    found: 2,
                },
            ),
            (
                |b| b.joints[1].offset[2] = f64::NAN,
                WriteError::NonFiniteOffset { joint: 1 },
            ),
            (
                |b| b.motion.push(0.0),
                WriteError::MotionLength {
                    frame_count: 2,
                    channel_count: 4,
                    values: 9,
                },
            ),
            (
                |b| b.frame_count = usize::MAX,
                WriteError::MotionLength {
                    frame_count: usize::MAX,
                    channel_count: 4,
                    values: 8,
                },
            ),
            (
                |b| b.motion[6] = f64::INFINITY,
                WriteError::NonFiniteMotion {
                    frame: 1,
                    channel: 2,
                },
            ),
            (
                |b| b.frame_time = 0.0,
                WriteError::BadFrameTime { value: 0.0 },
            ),
        ];
        for (break_it, expected) in cases {
            let mut bvh = small();
            break_it(&mut bvh);
            assert_eq!(bvh.validate(), Err(expected));
        }
    }

    #[test]
    fn nesting_deeper_than_the_reader_accepts_is_refused() {
        let joints = (0..=crate::MAX_DEPTH)
            .map(|i| joint(Some("j"), i.checked_sub(1), &[], 0))
            .collect();
        let bvh = Bvh {
            joints,
            frame_time: 1.0,
            frame_count: 0,
            motion: vec![],
        };
        assert_eq!(
            bvh.validate(),
            Err(WriteError::TooDeep {
                joint: crate::MAX_DEPTH,
                max: crate::MAX_DEPTH
            })
        );
    }
}
