//! Joint-name tokens: splitting a name into lowercase role tokens and reading its side
//! (see the [parent module](super) for the conventions).

use crate::side::Side;

/// Lowercase role tokens of a joint name: split at separators and camelCase boundaries,
/// namespace (`mixamorig:`) dropped — how joints are recognized by role.
pub fn name_tokens(name: &str) -> Vec<String> {
    let name = name.rsplit(':').next().unwrap_or(name);
    let chars: Vec<char> = name.chars().collect();
    let mut out = Vec::new();
    let mut cur = String::new();
    for (i, &c) in chars.iter().enumerate() {
        if !c.is_ascii_alphanumeric() {
            if !cur.is_empty() {
                out.push(std::mem::take(&mut cur));
            }
            continue;
        }
        let prev = i.checked_sub(1).map(|k| chars[k]);
        let next = chars.get(i + 1).copied();
        let boundary = c.is_ascii_uppercase()
            && prev.is_some_and(|p| {
                p.is_ascii_lowercase()
                    || p.is_ascii_digit()
                    || (p.is_ascii_uppercase() && next.is_some_and(|n| n.is_ascii_lowercase()))
            });
        if boundary && !cur.is_empty() {
            out.push(std::mem::take(&mut cur));
        }
        cur.push(c.to_ascii_lowercase());
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    // Character Creator's prefix.
    if out.len() > 2 && out[0] == "cc" && out[1] == "base" {
        out.drain(..2);
    }
    out
}

/// The side a token names: `right`/`r` or `left`/`l`.
pub(super) fn side_token(token: &str) -> Option<Side> {
    match token {
        "right" | "r" => Some(Side::Right),
        "left" | "l" => Some(Side::Left),
        _ => None,
    }
}

/// The side the first side token of `tokens` ([`name_tokens`]) names, if any.
pub fn side_of(tokens: &[String]) -> Option<Side> {
    tokens.iter().find_map(|t| side_token(t))
}

/// The name without its side tokens, joined: `Shoulder_R` → `shoulder`.
pub(super) fn role_word(tokens: &[String]) -> String {
    tokens
        .iter()
        .filter(|t| side_token(t).is_none())
        .map(String::as_str)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokenizes_the_conventions() {
        assert_eq!(
            name_tokens("mixamorig:RightForeArm"),
            ["right", "fore", "arm"]
        );
        assert_eq!(name_tokens("CC_Base_R_Upperarm"), ["r", "upperarm"]);
        assert_eq!(name_tokens("RHipJoint"), ["r", "hip", "joint"]);
        assert_eq!(name_tokens("LowerArm_R"), ["lower", "arm", "r"]);
    }
}
