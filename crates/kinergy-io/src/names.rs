//! Unknown names (joints, scene objects, DoFs): "did you mean …" by edit distance, and the
//! list — one message for every front end.

/// Levenshtein distance between `a` and `b`, ignoring case.
fn distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.to_lowercase().chars().collect();
    let b: Vec<char> = b.to_lowercase().chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.iter().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let above = row[j + 1];
            row[j + 1] = (above + 1)
                .min(row[j] + 1)
                .min(diagonal + usize::from(ca != cb));
            diagonal = above;
        }
    }
    row[b.len()]
}

/// The known name nearest to `name` when it is near enough to be a slip (at most a third of
/// its letters differ, at least one; a case-only difference always counts).
pub fn nearest<'a>(name: &str, known: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let limit = (name.chars().count() / 3).max(1);
    known
        .into_iter()
        .map(|k| (distance(name, k), k))
        .filter(|(d, _)| *d <= limit)
        .min_by_key(|(d, _)| *d)
        .map(|(_, k)| k)
}

/// "no {what} `name`; did you mean `x`? {what}s: a, b, c" — the message for an unknown name.
pub fn unknown(what: &str, name: &str, known: &[&str]) -> String {
    let guess = nearest(name, known.iter().copied())
        .map_or_else(String::new, |k| format!(" did you mean `{k}`?"));
    format!("no {what} `{name}`;{guess} {what}s: {}", known.join(", "))
}

#[cfg(test)]
mod tests {
    use super::{nearest, unknown};

    #[test]
    fn a_slip_is_matched_and_a_stranger_is_not() {
        let known = ["RightArm", "RightForeArm", "RightHand"];
        assert_eq!(nearest("RightForeArn", known), Some("RightForeArm"));
        assert_eq!(nearest("rightarm", known), Some("RightArm"));
        assert_eq!(nearest("Spine", known), None);
    }

    #[test]
    fn the_message_guesses_and_lists() {
        let m = unknown("object", "gray_book", &["grey_book", "red_book"]);
        assert_eq!(
            m,
            "no object `gray_book`; did you mean `grey_book`? objects: grey_book, red_book"
        );
        let m = unknown("object", "lamp", &["grey_book", "red_book"]);
        assert_eq!(m, "no object `lamp`; objects: grey_book, red_book");
    }
}
