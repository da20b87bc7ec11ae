//! Versioned JSON documents: every Kinergy file format that is JSON (parameters,
//! checkpoints, scenes, parameter fields) carries a top-level `format_version`, is read by
//! [`parse_versioned`] and written by [`write_json`].
//!
//! The rule, the same for every format:
//! 1. the text must be JSON (else [`JsonError::Syntax`], with line and column);
//! 2. a numeric `format_version` other than the one this build reads is refused before
//!    anything else is looked at ([`JsonError::Version`]), so a file from a newer Kinergy
//!    says so instead of complaining about a field it does not know;
//! 3. the document is decoded into its type; a missing, unknown or ill-typed field is
//!    named by its path (`objects[0].shape.radius`) with line and column
//!    ([`JsonError::Field`]).

use std::io;
use std::path::Path;

use serde::Serialize;
use serde::de::DeserializeOwned;

/// Why a versioned JSON document could not be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum JsonError {
    /// The text is not JSON.
    #[error("{message} at line {line} column {column}")]
    Syntax {
        /// serde_json's message, without the position.
        message: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
    },
    /// The document's `format_version` is not the one this build reads.
    #[error("`format_version` is {found}, this version of Kinergy reads {expected}")]
    Version {
        /// The version found.
        found: u64,
        /// The version this build reads.
        expected: u32,
    },
    /// A field is missing, unknown or has the wrong type or value.
    #[error("{}{message} at line {line} column {column}", field_prefix(field))]
    Field {
        /// The field's path (`objects[0].shape`); `.` for the top level.
        field: String,
        /// What is wrong, without the position.
        message: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
    },
}

impl crate::Classify for JsonError {
    /// A JSON document that does not read is the input's fault; the error that wraps it
    /// (a parameters file's, a scene's) may say more precisely whose.
    fn kind(&self) -> crate::ErrorKind {
        crate::ErrorKind::Input
    }
}

fn field_prefix(field: &str) -> String {
    if field == "." {
        String::new()
    } else {
        format!("`{field}`: ")
    }
}

impl JsonError {
    /// The field the error is about, when it is about one (`format_version` for a
    /// version mismatch).
    pub fn field(&self) -> Option<&str> {
        match self {
            JsonError::Syntax { .. } => None,
            JsonError::Version { .. } => Some("format_version"),
            JsonError::Field { field, .. } => Some(field),
        }
    }

    /// What is wrong and where in the text, without the field: for messages that show
    /// the field separately.
    pub fn detail(&self) -> String {
        match self {
            JsonError::Syntax {
                message,
                line,
                column,
            }
            | JsonError::Field {
                message,
                line,
                column,
                ..
            } => format!("{message} at line {line} column {column}"),
            JsonError::Version { .. } => self.message(),
        }
    }

    /// What is wrong, without the field and the position.
    pub fn message(&self) -> String {
        match self {
            JsonError::Syntax { message, .. } | JsonError::Field { message, .. } => message.clone(),
            JsonError::Version { found, expected } => {
                format!("this version of Kinergy reads format {expected}, found {found}")
            }
        }
    }
}

/// serde_json's message without the " at line L column C" it appends, quoting at most
/// [`crate::MAX_QUOTED_CHARS`] characters of the input (a damaged file may hold a string
/// of any size, which serde_json's message would repeat whole).
fn bare_message(e: &serde_json::Error) -> String {
    let text = e.to_string();
    let suffix = format!(" at line {} column {}", e.line(), e.column());
    let bare = text.strip_suffix(&suffix).unwrap_or(&text);
    crate::clip_text(bare, 2 * crate::MAX_QUOTED_CHARS).into_owned()
}

/// Refuses a `format_version` other than `expected` (for formats that decode the
/// version themselves).
pub fn check_version(found: u64, expected: u32) -> Result<(), JsonError> {
    if found == u64::from(expected) {
        Ok(())
    } else {
        Err(JsonError::Version { found, expected })
    }
}

/// Decodes a versioned document of type `T` from `text` (the rule in the module docs).
pub fn parse_versioned<T: DeserializeOwned>(text: &str, expected: u32) -> Result<T, JsonError> {
    let syntax = |e: serde_json::Error| JsonError::Syntax {
        message: bare_message(&e),
        line: e.line(),
        column: e.column(),
    };
    let value: serde_json::Value = serde_json::from_str(text).map_err(syntax)?;
    if let Some(found) = value
        .get("format_version")
        .and_then(serde_json::Value::as_u64)
    {
        check_version(found, expected)?;
    }
    drop(value);
    let de = &mut serde_json::Deserializer::from_str(text);
    serde_path_to_error::deserialize(de).map_err(|e| {
        let field = crate::clip_text(&e.path().to_string(), crate::MAX_QUOTED_CHARS).into_owned();
        let inner = e.into_inner();
        JsonError::Field {
            field,
            message: bare_message(&inner),
            line: inner.line(),
            column: inner.column(),
        }
    })
}

/// Pretty JSON with a final newline.
pub fn to_pretty_json<T: Serialize + ?Sized>(value: &T) -> Result<String, serde_json::Error> {
    let mut text = serde_json::to_string_pretty(value)?;
    text.push('\n');
    Ok(text)
}

/// Writes `value` as pretty JSON, atomically (see [`crate::write_atomic`]).
pub fn write_json<T: Serialize + ?Sized>(path: &Path, value: &T) -> io::Result<()> {
    let text = to_pretty_json(value).map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))?;
    write_json_text(path, &text)
}

/// Writes JSON `text` atomically, refusing (nothing written) a text longer than
/// [`crate::MAX_JSON_BYTES`], the most any Kinergy reader accepts: what Kinergy writes, it
/// reads back (a per-person fit of 100,000 segment rows wrote a 51 MB parameters file every
/// reader then refused).
pub fn write_json_text(path: &Path, text: &str) -> io::Result<()> {
    let size = text.len() as u64;
    if size > crate::MAX_JSON_BYTES {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "the file would be {:.1} MB, over the {} a Kinergy reader accepts; nothing \
                 written (fit fewer reaches into one file, e.g. --per clip)",
                size as f64 / 1e6,
                crate::format_limit(crate::MAX_JSON_BYTES)
            ),
        ));
    }
    crate::write_atomic(path, text.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Deserialize;

    #[test]
    fn a_text_no_reader_accepts_is_not_written() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("big.json");
        let big = format!("\"{}\"", "x".repeat(crate::MAX_JSON_BYTES as usize));
        let err = write_json_text(&path, &big).expect_err("over the cap");
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        assert!(err.to_string().contains("16 MiB"), "{err}");
        assert!(!path.exists());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        let fits = format!("\"{}\"", "x".repeat(crate::MAX_JSON_BYTES as usize - 2));
        write_json_text(&path, &fits).expect("at the cap");
        assert_eq!(
            std::fs::metadata(&path).unwrap().len(),
            crate::MAX_JSON_BYTES
        );
    }

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Doc {
        format_version: u32,
        items: Vec<Item>,
    }

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Item {
        size: f64,
    }

    fn parse(text: &str) -> Result<Doc, JsonError> {
        parse_versioned(text, 1)
    }

    #[test]
    fn reads_a_good_document() {
        let doc = parse(r#"{"format_version": 1, "items": [{"size": 2.5}]}"#).unwrap();
        assert_eq!(doc.items, vec![Item { size: 2.5 }]);
    }

    #[test]
    fn errors_never_quote_a_huge_input_whole() {
        let huge = "A".repeat(5_000_000);
        for text in [
            format!(r#"{{"format_version": 1, "items": [{{"size": "{huge}"}}]}}"#),
            format!(r#"{{"format_version": 1, "items": [{{"{huge}": 1}}]}}"#),
        ] {
            let e = parse(&text).unwrap_err();
            let shown = e.to_string();
            assert!(shown.len() < 1000, "{} bytes", shown.len());
            assert!(shown.contains("more characters"), "{shown}");
        }
    }

    #[test]
    fn syntax_errors_have_a_position() {
        let e = parse("{\n  \"format_version\": 1,\n  oops\n}").unwrap_err();
        assert!(matches!(e, JsonError::Syntax { line: 3, .. }), "{e:?}");
        assert!(e.to_string().ends_with("at line 3 column 3"), "{e}");
    }

    #[test]
    fn another_version_is_refused_before_unknown_fields() {
        let e = parse(r#"{"format_version": 7, "items": [], "new_thing": 1}"#).unwrap_err();
        assert_eq!(
            e,
            JsonError::Version {
                found: 7,
                expected: 1
            }
        );
        assert_eq!(e.field(), Some("format_version"));
        assert_eq!(
            e.to_string(),
            "`format_version` is 7, this version of Kinergy reads 1"
        );
    }

    #[test]
    fn field_errors_name_the_path() {
        let e = parse(r#"{"format_version": 1, "items": [{"size": "big"}]}"#).unwrap_err();
        assert_eq!(e.field(), Some("items[0].size"));
        assert!(
            e.to_string().starts_with("`items[0].size`: invalid type"),
            "{e}"
        );
        let e = parse(r#"{"format_version": 1}"#).unwrap_err();
        assert_eq!(e.field(), Some("."));
        assert!(e.to_string().starts_with("missing field `items`"), "{e}");
    }

    #[test]
    fn written_documents_read_back() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("doc.json");
        let doc = Doc {
            format_version: 1,
            items: vec![Item { size: 0.1 }, Item { size: -3e-9 }],
        };
        write_json(&path, &doc).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.ends_with("}\n"));
        assert_eq!(parse(&text).unwrap(), doc);
    }
}
