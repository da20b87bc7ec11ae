//! Who moves in a take, and which motion it is: the **person rule**, written once for
//! every command that groups takes by person — a library's `library.csv` and shard records
//! (`fit --out-dir`, `collect`) and `compare --per person`.
//!
//! A take is seen as a library sees it ([`TakeAt`]): its path from the library's root (the
//! takes' common folder), and the root. The rules ([`PersonRule`], spelled as `--person`
//! spells them):
//!
//! | rule | the person | example |
//! |---|---|---|
//! | `auto` (default) | the segments file's `person` where the take's reaches come from one; else the performer the file name gives (Bandai, CMU); else `folder` | `dataset-2_raise-up-right-hand_elderly_012.bvh` → `elderly`; `64_26.bvh` → `64`; `p01/r03.bvh` → `p01` |
//! | `folder` | the take's folder from the root (`/`-separated); the root's own takes get the root's name | `p01/r03.bvh` → `p01`; `site1/p01/r03.bvh` → `site1/p01`; `r03.bvh` in `bandai/` → `bandai` |
//! | `file` (alias `prefix`) | the file name, by [`FileName`]'s patterns | `active_003.bvh` → `active` |
//! | `regex:PATTERN` | the group `person` of PATTERN, or else its first group, searched for in the take's path from the root (`/`-separated); a take it does not match is an error naming the take and the pattern | `regex:^(p\d+)/` |
//! | `segments` | the segments file's `person` column (its empty cells: the file name's performer, else the folder's name) | |
//! | `map:FILE.csv` | a table of two columns, `take,person` (and an optional `motion`): the take's path from the root, as `library.csv`'s `clip` spells it; takes missing from it are an error naming them | |
//!
//! The file name's patterns ([`FileName::of`], on the name without its extension):
//! - **Bandai Namco** `dataset-N_MOTION_STYLE_NNN` (`dataset-2_raise-up-right-hand_elderly_012`):
//!   person STYLE, motion MOTION;
//! - **CMU** `SS_TT`, digits both (`64_26`): person SS, the subject (as written: `06_14` → `06`);
//! - **numbered** `STYLE_NNN` (`active_003`), and any `PREFIX_REST`: person PREFIX, the name up to
//!   its last `_`;
//! - otherwise the name itself.
//!
//! `auto` trusts only the first two (their names say who performs); a numbered name such as
//! `take_001.bvh` says no one, so `auto` gives such takes their folder.
//!
//! The **motion** of a take ([`Who::motion`]): a `regex:` pattern's group `motion`, a map's
//! `motion` column, else Bandai's MOTION part, else none — whichever rule gives the person.
//!
//! ```
//! use std::path::Path;
//! use kinergy_train::who::{PersonRule, TakeAt};
//!
//! let rule: PersonRule = "auto".parse()?;
//! let root = Path::new("/data/bandai");
//! let take = TakeAt::new(root, Path::new("dataset-2_raise-up-right-hand_elderly_012.bvh"));
//! let who = rule.who(take, None)?;
//! assert_eq!(who.person, "elderly");
//! assert_eq!(who.motion.as_deref(), Some("raise-up-right-hand"));
//!
//! let rule: PersonRule = r"regex:^(?P<person>p\d+)/".parse()?;
//! let who = rule.who(TakeAt::new(root, Path::new("p07/r01.bvh")), None)?;
//! assert_eq!(who.person, "p07");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::collections::HashMap;
use std::fmt;
use std::path::{Component, Path, PathBuf};
use std::str::FromStr;

/// How many takes an error names (the rest are counted).
const NAMED: usize = 8;

/// The largest mapping file read, bytes.
const MAX_MAP_BYTES: u64 = 256 << 20;

/// What the rules accept, as the errors say it.
const RULES: &str = "auto, folder, file (or prefix), segments, regex:PATTERN or map:FILE.csv";

/// Why a person rule could not be read or could not say who moves in a take.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum WhoError {
    /// The rule's text is none of the rules.
    #[error("`{}`: not a person rule: expected {RULES}", kinergy_io::clip_text(.text, 80))]
    Rule {
        /// The text given.
        text: String,
    },
    /// A `regex:` pattern that does not compile, or has no group to take the person from.
    #[error("regex:{}: {why}", kinergy_io::clip_text(.pattern, 200))]
    Pattern {
        /// The pattern.
        pattern: String,
        /// What is wrong with it.
        why: String,
    },
    /// Takes a `regex:` pattern does not match (or whose person group is empty).
    #[error(
        "regex:{}: {} take{} not matched (or with an empty person group): {}: a pattern is \
         searched for in each take's path from the library's root, `/`-separated",
        kinergy_io::clip_text(.pattern, 200),
        .takes.len(),
        if .takes.len() == 1 { "" } else { "s" },
        kinergy_io::list_some(.takes, NAMED)
    )]
    Unmatched {
        /// The pattern.
        pattern: String,
        /// The takes it does not match, by their paths from the root.
        takes: Vec<String>,
    },
    /// A mapping file that cannot be read, or a line of it that is wrong.
    #[error("{}{}: {why}", .path.display(), .line.map_or_else(String::new, |l| format!(" line {l}")))]
    Map {
        /// The mapping file.
        path: PathBuf,
        /// The line (1-based), when the error is about one.
        line: Option<usize>,
        /// What is wrong.
        why: String,
    },
    /// Takes a mapping file does not list.
    #[error(
        "{}: {} take{} not listed: {}: add a row `take,person` for each (the take's path from \
         the library's root, as library.csv's `clip` spells it)",
        .path.display(),
        .takes.len(),
        if .takes.len() == 1 { " is" } else { "s are" },
        kinergy_io::list_some(.takes, NAMED)
    )]
    NotMapped {
        /// The mapping file.
        path: PathBuf,
        /// The takes missing from it, by their paths from the root.
        takes: Vec<String>,
    },
    /// `segments` for takes that come with no segments file.
    #[error(
        "--person segments needs --segments FILE (a segments file naming each take's person): \
         {} take{} come{} with none: {}",
        .takes.len(),
        if .takes.len() == 1 { "" } else { "s" },
        if .takes.len() == 1 { "s" } else { "" },
        kinergy_io::list_some(.takes, NAMED)
    )]
    NoSegments {
        /// The takes, by their paths from the root.
        takes: Vec<String>,
    },
}

impl kinergy_io::Classify for WhoError {
    /// Every one is the input's fault: the rule, its pattern or file, or the takes it is
    /// given.
    fn kind(&self) -> kinergy_io::ErrorKind {
        kinergy_io::ErrorKind::Input
    }
}

/// A take as the person rule sees it: its path from the library's root, and the root.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TakeAt<'a> {
    /// The library's root (the takes' common folder): its name is the person of its own
    /// takes under `folder`.
    pub root: &'a Path,
    /// The take's path from the root (`p01/r03.bvh`, or `r03.bvh` for the root's own).
    pub path: &'a Path,
}

impl<'a> TakeAt<'a> {
    /// The take at `path` from `root`.
    pub fn new(root: &'a Path, path: &'a Path) -> TakeAt<'a> {
        TakeAt { root, path }
    }

    /// Its path from the root, `/`-separated, plain names only (as a library's records and
    /// `library.csv` spell it).
    pub fn slash_path(&self) -> String {
        slash(self.path)
    }

    /// The take's folder from the root, `/`-separated; the root's own takes: the root's
    /// name (`/` for a root without one).
    pub fn folder(&self) -> String {
        let folder = slash(self.path.parent().unwrap_or(Path::new("")));
        if !folder.is_empty() {
            return folder;
        }
        self.root.file_name().map_or_else(
            || self.root.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        )
    }
}

/// `path`'s plain names joined by `/`.
fn slash(path: &Path) -> String {
    path.components()
        .filter_map(|c| match c {
            Component::Normal(name) => Some(name.to_string_lossy()),
            _ => None,
        })
        .collect::<Vec<_>>()
        .join("/")
}

/// Who moves in a take, and which motion it is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Who {
    /// The person (never empty).
    pub person: String,
    /// The motion, where the rule or the file name says it (Bandai's MOTION part).
    pub motion: Option<String>,
}

/// What a take's file name says, by the patterns datasets name their files with (see the
/// [module docs](self)).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FileName {
    /// Bandai Namco's `dataset-N_MOTION_STYLE_NNN`.
    Bandai {
        /// MOTION (`raise-up-right-hand`).
        motion: String,
        /// STYLE (`elderly`), the person.
        style: String,
    },
    /// CMU's `SS_TT`, digits both.
    Cmu {
        /// SS, the subject (the person), as written.
        subject: String,
        /// TT, the trial.
        trial: String,
    },
    /// `STYLE_NNN`, or any `PREFIX_REST`: the name up to its last `_`.
    Prefixed {
        /// PREFIX (`active`), the person.
        prefix: String,
    },
    /// None of them: the name without its extension.
    Plain {
        /// The name.
        stem: String,
    },
}

impl FileName {
    /// What the file name of `path` says (its name without the extension).
    pub fn of(path: &Path) -> FileName {
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        FileName::of_stem(&stem)
    }

    /// What a file name without its extension says.
    pub fn of_stem(stem: &str) -> FileName {
        let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
        if let Some(rest) = stem.strip_prefix("dataset-")
            && let Some((set, rest)) = rest.split_once('_')
            && digits(set)
            && let Some((rest, number)) = rest.rsplit_once('_')
            && digits(number)
            && let Some((motion, style)) = rest.rsplit_once('_')
            && !motion.is_empty()
            && !style.is_empty()
        {
            return FileName::Bandai {
                motion: motion.to_string(),
                style: style.to_string(),
            };
        }
        if let Some((subject, trial)) = stem.split_once('_')
            && digits(subject)
            && digits(trial)
        {
            return FileName::Cmu {
                subject: subject.to_string(),
                trial: trial.to_string(),
            };
        }
        match stem.rsplit_once('_') {
            Some((prefix, _)) if !prefix.is_empty() => FileName::Prefixed {
                prefix: prefix.to_string(),
            },
            _ => FileName::Plain {
                stem: stem.to_string(),
            },
        }
    }

    /// The person the name gives under `file`: STYLE, SS, PREFIX, or the name.
    pub fn person(&self) -> &str {
        match self {
            FileName::Bandai { style, .. } => style,
            FileName::Cmu { subject, .. } => subject,
            FileName::Prefixed { prefix } => prefix,
            FileName::Plain { stem } => stem,
        }
    }

    /// The performer a dataset's name says (Bandai's STYLE, CMU's subject): what `auto`
    /// trusts. `None` for the other names.
    pub fn performer(&self) -> Option<&str> {
        match self {
            FileName::Bandai { style, .. } => Some(style),
            FileName::Cmu { subject, .. } => Some(subject),
            FileName::Prefixed { .. } | FileName::Plain { .. } => None,
        }
    }

    /// The motion the name says (Bandai's MOTION), if any.
    pub fn motion(&self) -> Option<&str> {
        match self {
            FileName::Bandai { motion, .. } => Some(motion),
            _ => None,
        }
    }
}

/// Who moves in a capture when nobody says, knowing nothing of a library: the performer
/// its file name gives (Bandai, CMU), else the name of its folder (empty when there is
/// none). A segments file's empty `person` cells, and `segment --manifest`'s, are this.
pub fn guess_person(clip: &Path) -> String {
    if let Some(person) = FileName::of(clip).performer() {
        return person.to_string();
    }
    let absolute = std::path::absolute(clip).unwrap_or_else(|_| clip.to_path_buf());
    absolute
        .parent()
        .and_then(Path::file_name)
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// A `regex:` pattern, compiled once; equal to another of the same text.
#[derive(Debug, Clone)]
pub struct PersonPattern {
    regex: regex::Regex,
    /// The group the person is taken from: `person`, or else 1.
    group: PatternGroup,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum PatternGroup {
    Named,
    First,
}

impl PersonPattern {
    /// Compiles `pattern` (the `regex` crate's syntax), which must have a group named
    /// `person` or at least one group.
    pub fn new(pattern: &str) -> Result<PersonPattern, WhoError> {
        let refuse = |why: String| WhoError::Pattern {
            pattern: pattern.to_string(),
            why,
        };
        let regex = regex::Regex::new(pattern).map_err(|e| refuse(e.to_string()))?;
        let named = regex.capture_names().any(|n| n == Some("person"));
        let group = match (named, regex.captures_len()) {
            (true, _) => PatternGroup::Named,
            (false, n) if n > 1 => PatternGroup::First,
            _ => {
                return Err(refuse(
                    "no group to take the person from: name one `(?P<person>…)`, or put the \
                     person in the first group `(…)`"
                        .into(),
                ));
            }
        };
        Ok(PersonPattern { regex, group })
    }

    /// The pattern's text.
    pub fn as_str(&self) -> &str {
        self.regex.as_str()
    }

    /// The person (and the group `motion`, where the pattern has one and it matched) in the
    /// path `text`; `None` when the pattern does not match or its person group is empty.
    pub fn find(&self, text: &str) -> Option<Who> {
        let captures = self.regex.captures(text)?;
        let person = match self.group {
            PatternGroup::Named => captures.name("person"),
            PatternGroup::First => captures.get(1),
        }
        .map(|m| m.as_str())
        .filter(|p| !p.is_empty())?;
        let motion = captures
            .name("motion")
            .map(|m| m.as_str().to_string())
            .filter(|m| !m.is_empty());
        Some(Who {
            person: person.to_string(),
            motion,
        })
    }
}

impl PartialEq for PersonPattern {
    fn eq(&self, other: &PersonPattern) -> bool {
        self.as_str() == other.as_str()
    }
}

/// A mapping file's table: each take's person (and motion), by the take's path from the
/// library's root.
#[derive(Debug, Clone, PartialEq)]
pub struct PersonMap {
    path: PathBuf,
    blake3: String,
    people: HashMap<String, Who>,
}

impl PersonMap {
    /// Reads the mapping file at `path`: CSV with a header naming the columns `take` and
    /// `person`, and optionally `motion`, in any order; lines starting with `#` are
    /// comments, spaces around a cell are ignored. A take is its path from the library's
    /// root, `/`-separated (a leading `./` and `\` separators are read as such); each take
    /// once, each with a person. Rows of takes not in the library are ignored (one map can
    /// serve a whole dataset). Errors name the file and the line.
    pub fn read(path: &Path) -> Result<PersonMap, WhoError> {
        let refuse = |line: Option<usize>, why: String| WhoError::Map {
            path: path.to_path_buf(),
            line,
            why,
        };
        let bytes = kinergy_io::read_limited(path, MAX_MAP_BYTES)
            .map_err(|e| refuse(None, format!("cannot read the mapping file: {e}")))?;
        let blake3 = crate::library::hash_bytes(&bytes);
        let text = String::from_utf8(bytes).map_err(|e| {
            refuse(
                None,
                format!(
                    "not UTF-8 text (a byte at {} is not)",
                    e.utf8_error().valid_up_to()
                ),
            )
        })?;
        let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
        let mut reader = csv::ReaderBuilder::new()
            .comment(Some(b'#'))
            .trim(csv::Trim::All)
            .flexible(false)
            .from_reader(text.as_bytes());
        let header = reader
            .headers()
            .map_err(|e| refuse(Some(1), e.to_string()))?
            .clone();
        let header_line = header.position().map_or(1, |p| p.line() as usize);
        let mut column: HashMap<&str, usize> = HashMap::new();
        for (i, name) in header.iter().enumerate() {
            let known = ["take", "person", "motion"]
                .into_iter()
                .find(|c| *c == name)
                .ok_or_else(|| {
                    refuse(
                        Some(header_line),
                        format!(
                            "unknown column `{}`: a mapping file has `take,person` (and \
                             optionally `motion`)",
                            kinergy_io::clip_text(name, 40)
                        ),
                    )
                })?;
            if column.insert(known, i).is_some() {
                return Err(refuse(
                    Some(header_line),
                    format!("column `{known}` appears twice"),
                ));
            }
        }
        let (Some(&take_at), Some(&person_at)) = (column.get("take"), column.get("person")) else {
            return Err(refuse(
                Some(header_line),
                "the header needs the columns `take` and `person` (a mapping file is \
                 `take,person`, then one row per take)"
                    .into(),
            ));
        };
        let motion_at = column.get("motion").copied();
        let mut people: HashMap<String, Who> = HashMap::new();
        let mut first_line: HashMap<String, usize> = HashMap::new();
        for record in reader.records() {
            let record = record.map_err(|e| {
                let line = e.position().map(|p| p.line() as usize);
                let why = match e.kind() {
                    csv::ErrorKind::UnequalLengths {
                        expected_len, len, ..
                    } => format!("{len} fields where the header has {expected_len}"),
                    _ => e.to_string(),
                };
                refuse(line, why)
            })?;
            let line = record.position().map_or(0, |p| p.line() as usize);
            let cell = |at: usize| record.get(at).unwrap_or("");
            let take = normalize_take(cell(take_at));
            if take.is_empty() {
                return Err(refuse(Some(line), "no take (an empty `take` cell)".into()));
            }
            let person = cell(person_at);
            if person.is_empty() {
                return Err(refuse(
                    Some(line),
                    format!(
                        "no person for {} (an empty `person` cell)",
                        kinergy_io::clip_text(&take, 80)
                    ),
                ));
            }
            let motion = motion_at
                .map(|at| cell(at).to_string())
                .filter(|m| !m.is_empty());
            if let Some(first) = first_line.insert(take.clone(), line) {
                return Err(refuse(
                    Some(line),
                    format!(
                        "{} is listed again (first on line {first}): one row per take",
                        kinergy_io::clip_text(&take, 80)
                    ),
                ));
            }
            people.insert(
                take,
                Who {
                    person: person.to_string(),
                    motion,
                },
            );
        }
        Ok(PersonMap {
            path: path.to_path_buf(),
            blake3,
            people,
        })
    }

    /// The mapping file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The BLAKE3 hash of the mapping file's bytes (a library records the map by it).
    pub fn blake3(&self) -> &str {
        &self.blake3
    }

    /// The person (and motion) the map lists for the take at `path` from the root.
    pub fn get(&self, path: &str) -> Option<&Who> {
        self.people.get(path)
    }
}

/// A mapping file's take as a path from the root: `/`-separated, no leading `./`.
fn normalize_take(cell: &str) -> String {
    let cell = cell.replace('\\', "/");
    cell.split('/')
        .filter(|part| !part.is_empty() && *part != ".")
        .collect::<Vec<_>>()
        .join("/")
}

/// Who moves in each take of a library (or of `compare --per person`): see the [module
/// docs](self) for each rule.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum PersonRule {
    /// The segments file's person where there is one, else the performer the file name
    /// gives (Bandai, CMU), else the folder.
    #[default]
    Auto,
    /// The take's folder from the root; the root's own takes: the root's name.
    Folder,
    /// The file name, by [`FileName`]'s patterns (`prefix` is its old spelling).
    File,
    /// The group `person` (or the first group) of a pattern searched for in the take's path
    /// from the root.
    Regex(PersonPattern),
    /// The segments file's `person` column.
    Segments,
    /// A mapping file's `take,person` rows.
    Map(PersonMap),
}

impl FromStr for PersonRule {
    type Err = WhoError;

    /// `auto`, `folder`, `file` (or `prefix`), `segments`, `regex:PATTERN` or
    /// `map:FILE.csv` (the file is read here).
    fn from_str(text: &str) -> Result<PersonRule, WhoError> {
        if let Some(pattern) = text.strip_prefix("regex:") {
            return PersonPattern::new(pattern).map(PersonRule::Regex);
        }
        if let Some(file) = text.strip_prefix("map:") {
            if file.is_empty() {
                return Err(WhoError::Rule { text: text.into() });
            }
            return PersonMap::read(Path::new(file)).map(PersonRule::Map);
        }
        match text.trim() {
            "auto" => Ok(PersonRule::Auto),
            "folder" => Ok(PersonRule::Folder),
            "file" | "prefix" => Ok(PersonRule::File),
            "segments" => Ok(PersonRule::Segments),
            _ => Err(WhoError::Rule { text: text.into() }),
        }
    }
}

impl fmt::Display for PersonRule {
    /// The rule as a library records it among its settings: its name, a pattern's text, a
    /// map's content hash (`map:` and 64 hexadecimal digits: the same map read anywhere).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PersonRule::Auto => f.write_str("auto"),
            PersonRule::Folder => f.write_str("folder"),
            PersonRule::File => f.write_str("file"),
            PersonRule::Regex(p) => write!(f, "regex:{}", p.as_str()),
            PersonRule::Segments => f.write_str("segments"),
            PersonRule::Map(m) => write!(f, "map:{}", m.blake3()),
        }
    }
}

impl PersonRule {
    /// Whether the rule reads the segments file's `person` column where a take has one:
    /// `auto` and `segments`.
    pub fn uses_segments(&self) -> bool {
        matches!(self, PersonRule::Auto | PersonRule::Segments)
    }

    /// Who moves in `take`, whose reach's segments-file row (if it comes from one) names
    /// `listed`.
    pub fn who(&self, take: TakeAt<'_>, listed: Option<&str>) -> Result<Who, WhoError> {
        self.try_who(take, listed)
            .map_err(|miss| miss.error(self, vec![take.slash_path()]))
    }

    /// [`who`](Self::who) for every take of `takes` (each with its `listed` person), in
    /// order; where some cannot be said, one error naming all of them.
    pub fn who_all<'t>(
        &self,
        takes: impl IntoIterator<Item = (TakeAt<'t>, Option<&'t str>)>,
    ) -> Result<Vec<Who>, WhoError> {
        let mut out = Vec::new();
        let mut missed: Vec<String> = Vec::new();
        let mut seen = std::collections::HashSet::new();
        let mut miss = None;
        for (take, listed) in takes {
            match self.try_who(take, listed) {
                Ok(who) => out.push(who),
                Err(m) => {
                    let path = take.slash_path();
                    if seen.insert(path.clone()) {
                        missed.push(path);
                    }
                    miss = Some(m);
                }
            }
        }
        match miss {
            None => Ok(out),
            Some(m) => Err(m.error(self, missed)),
        }
    }

    /// [`who_all`](Self::who_all) for captures named by their paths as given (a
    /// `compare`'s clips, not a library's takes): each seen from the deepest folder they
    /// share, as a library's takes are from its root.
    pub fn who_of_paths<'t>(
        &self,
        takes: impl IntoIterator<Item = (&'t Path, Option<&'t str>)>,
    ) -> Result<Vec<Who>, WhoError> {
        let takes: Vec<(PathBuf, Option<&str>)> = takes
            .into_iter()
            .map(|(path, listed)| (crate::library::names::canonical(path), listed))
            .collect();
        let canonical: Vec<PathBuf> = takes.iter().map(|(p, _)| p.clone()).collect();
        let root = crate::library::common_folder(&canonical);
        let relative: Vec<PathBuf> = canonical
            .iter()
            .map(|take| crate::library::relative_name(&root, take))
            .collect();
        self.who_all(
            relative
                .iter()
                .zip(&takes)
                .map(|(path, (_, listed))| (TakeAt::new(&root, path), *listed)),
        )
    }

    fn try_who(&self, take: TakeAt<'_>, listed: Option<&str>) -> Result<Who, Miss> {
        let name = FileName::of(take.path);
        let motion = name.motion().map(str::to_string);
        let by = |person: &str| Who {
            person: person.to_string(),
            motion: motion.clone(),
        };
        let listed = listed.filter(|p| !p.is_empty());
        Ok(match self {
            PersonRule::Auto => match (listed, name.performer()) {
                (Some(person), _) | (None, Some(person)) => by(person),
                (None, None) => by(&take.folder()),
            },
            PersonRule::Folder => by(&take.folder()),
            PersonRule::File => by(name.person()),
            PersonRule::Segments => by(listed.ok_or(Miss::Segments)?),
            PersonRule::Regex(pattern) => {
                let found = pattern.find(&take.slash_path()).ok_or(Miss::Pattern)?;
                Who {
                    motion: found.motion.or(motion),
                    ..found
                }
            }
            PersonRule::Map(map) => {
                let found = map.get(&take.slash_path()).ok_or(Miss::Map)?;
                Who {
                    person: found.person.clone(),
                    motion: found.motion.clone().or(motion),
                }
            }
        })
    }
}

/// Why a rule could not say who moves in a take.
#[derive(Debug, Clone, Copy)]
enum Miss {
    Segments,
    Pattern,
    Map,
}

impl Miss {
    fn error(self, rule: &PersonRule, takes: Vec<String>) -> WhoError {
        match (self, rule) {
            (Miss::Pattern, PersonRule::Regex(p)) => WhoError::Unmatched {
                pattern: p.as_str().to_string(),
                takes,
            },
            (Miss::Map, PersonRule::Map(m)) => WhoError::NotMapped {
                path: m.path().to_path_buf(),
                takes,
            },
            _ => WhoError::NoSegments { takes },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn who(rule: &str, root: &str, path: &str) -> Result<Who, WhoError> {
        let rule: PersonRule = rule.parse()?;
        rule.who(TakeAt::new(Path::new(root), Path::new(path)), None)
    }

    fn person(rule: &str, root: &str, path: &str) -> String {
        who(rule, root, path).unwrap().person
    }

    #[test]
    fn bandai_names_give_the_style_and_the_motion() {
        let take = "dataset-2_raise-up-right-hand_elderly_012.bvh";
        for rule in ["auto", "file", "prefix"] {
            let w = who(rule, "/data/bandai", take).unwrap();
            assert_eq!(w.person, "elderly", "{rule}");
            assert_eq!(w.motion.as_deref(), Some("raise-up-right-hand"), "{rule}");
        }
        // The motion whatever rule gives the person.
        let w = who("folder", "/data/bandai", take).unwrap();
        assert_eq!(
            (w.person.as_str(), w.motion.as_deref()),
            ("bandai", Some("raise-up-right-hand"))
        );
        assert_eq!(
            FileName::of_stem("dataset-1_walk_left_not-confident_003"),
            FileName::Bandai {
                motion: "walk_left".into(),
                style: "not-confident".into()
            }
        );
        // Not quite Bandai: no number, or no set.
        assert_eq!(
            person("file", "/d", "dataset-1_bow_active.bvh"),
            "dataset-1_bow"
        );
        assert_eq!(person("auto", "/d", "dataset-x_bow_active_001.bvh"), "d");
    }

    #[test]
    fn cmu_names_give_the_subject() {
        assert_eq!(person("auto", "/data/cmu", "64_26.bvh"), "64");
        assert_eq!(person("file", "/data/cmu", "06_14.bvh"), "06");
        assert_eq!(who("auto", "/data/cmu", "64_26.bvh").unwrap().motion, None);
        assert_eq!(
            FileName::of_stem("26_10"),
            FileName::Cmu {
                subject: "26".into(),
                trial: "10".into()
            }
        );
        // Letters in either part: not CMU's.
        assert_eq!(FileName::of_stem("cmu_12").performer(), None);
        assert_eq!(FileName::of_stem("12_01_walk").performer(), None);
    }

    #[test]
    fn numbered_names_give_their_prefix_under_file_only() {
        assert_eq!(
            person("file", "/data/bandai-raise-left", "active_003.bvh"),
            "active"
        );
        assert_eq!(person("prefix", "/d", "cmu_12_01_walk.bvh"), "cmu_12_01");
        assert_eq!(person("file", "/d", "r03.bvh"), "r03");
        assert_eq!(person("file", "/d", "_001.bvh"), "_001");
        // auto does not trust a numbered name: the folder.
        assert_eq!(
            person("auto", "/data/bandai-raise-left", "active_003.bvh"),
            "bandai-raise-left"
        );
        assert_eq!(person("auto", "/data", "p01/take_001.bvh"), "p01");
    }

    #[test]
    fn folders_are_the_take_s_folder_from_the_root_or_the_root_s_name() {
        assert_eq!(person("folder", "/data/synthetic", "p01/r03.bvh"), "p01");
        assert_eq!(person("folder", "/data", "site1/p01/r03.bvh"), "site1/p01");
        assert_eq!(person("folder", "/data/p01", "r03.bvh"), "p01");
        assert_eq!(person("auto", "/data", "p02/r03.bvh"), "p02");
        assert_eq!(person("folder", "/", "r03.bvh"), "/");
    }

    #[test]
    fn a_pattern_takes_its_named_group_or_its_first() {
        let w = who(
            r"regex:^(?P<motion>[a-z]+)/(?P<person>s\d+)_",
            "/d",
            "lift/s07_001.bvh",
        )
        .unwrap();
        assert_eq!(
            (w.person.as_str(), w.motion.as_deref()),
            ("s07", Some("lift"))
        );
        assert_eq!(person(r"regex:(p\d+)", "/d", "group-a/p12/r01.bvh"), "p12");
        // Searched, not anchored, in the `/`-separated path from the root.
        assert_eq!(person(r"regex:/(\w+)_", "/d", "x/alice_2.bvh"), "alice");
        // Bandai's motion when the pattern has none.
        let w = who(
            r"regex:_([a-z]+)_\d+\.bvh$",
            "/d",
            "dataset-2_bow_proud_001.bvh",
        )
        .unwrap();
        assert_eq!(
            (w.person.as_str(), w.motion.as_deref()),
            ("proud", Some("bow"))
        );
    }

    #[test]
    fn a_bad_pattern_is_refused_saying_why() {
        let e = "regex:(p\\d+".parse::<PersonRule>().unwrap_err();
        assert!(matches!(e, WhoError::Pattern { .. }), "{e}");
        let text = e.to_string();
        assert!(
            text.starts_with("regex:(p\\d+: ") && text.contains("unclosed group"),
            "{text}"
        );
        let e = "regex:p\\d+".parse::<PersonRule>().unwrap_err().to_string();
        assert!(e.contains("no group to take the person from"), "{e}");
        let e = "someone".parse::<PersonRule>().unwrap_err().to_string();
        assert_eq!(
            e,
            "`someone`: not a person rule: expected auto, folder, file (or prefix), segments, \
             regex:PATTERN or map:FILE.csv"
        );
        assert!("map:".parse::<PersonRule>().is_err());
    }

    #[test]
    fn a_take_the_pattern_does_not_match_is_named_with_the_pattern() {
        let rule: PersonRule = r"regex:^(p\d+)/".parse().unwrap();
        let root = Path::new("/data");
        let e = rule
            .who(TakeAt::new(root, Path::new("q1/r01.bvh")), None)
            .unwrap_err();
        assert_eq!(
            e,
            WhoError::Unmatched {
                pattern: r"^(p\d+)/".into(),
                takes: vec!["q1/r01.bvh".into()]
            }
        );
        assert!(
            e.to_string()
                .contains("regex:^(p\\d+)/: 1 take not matched"),
            "{e}"
        );
        // All of a library's unmatched takes in one error, each once; an empty group is no
        // person.
        let paths = ["p1/a.bvh", "q1/a.bvh", "q1/a.bvh", "q2/b.bvh"];
        let takes = paths
            .iter()
            .map(|p| (TakeAt::new(root, Path::new(p)), None));
        let e = rule.who_all(takes).unwrap_err();
        assert_eq!(
            e,
            WhoError::Unmatched {
                pattern: r"^(p\d+)/".into(),
                takes: vec!["q1/a.bvh".into(), "q2/b.bvh".into()]
            }
        );
        let rule: PersonRule = r"regex:^(x?)".parse().unwrap();
        assert!(
            rule.who(TakeAt::new(root, Path::new("a.bvh")), None)
                .is_err()
        );
    }

    #[test]
    fn a_mapping_file_names_each_take_s_person_and_refuses_takes_it_lacks() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("who.csv");
        std::fs::write(
            &path,
            "# who is who\ntake,person,motion\n./p01/r01.bvh, alice ,lift\np01/r02.bvh,bob,\n",
        )
        .unwrap();
        let rule: PersonRule = format!("map:{}", path.display()).parse().unwrap();
        let root = Path::new("/data");
        let w = rule
            .who(TakeAt::new(root, Path::new("p01/r01.bvh")), None)
            .unwrap();
        assert_eq!(
            (w.person.as_str(), w.motion.as_deref()),
            ("alice", Some("lift"))
        );
        let w = rule
            .who(TakeAt::new(root, Path::new("p01/r02.bvh")), None)
            .unwrap();
        assert_eq!((w.person.as_str(), w.motion), ("bob", None));
        let takes = ["p01/r01.bvh", "p01/r03.bvh", "r04.bvh"]
            .map(|p| (TakeAt::new(root, Path::new(p)), None));
        let e = rule.who_all(takes).unwrap_err();
        assert_eq!(
            e,
            WhoError::NotMapped {
                path: path.clone(),
                takes: vec!["p01/r03.bvh".into(), "r04.bvh".into()]
            }
        );
        assert!(
            e.to_string()
                .contains("2 takes are not listed: p01/r03.bvh, r04.bvh"),
            "{e}"
        );
        // The rule as recorded: the map's content, not its path.
        let PersonRule::Map(map) = &rule else {
            panic!("a map")
        };
        assert_eq!(rule.to_string(), format!("map:{}", map.blake3()));
        // Malformed maps, by line.
        for (text, expected) in [
            ("take,who\na,b\n", "line 1: unknown column `who`"),
            (
                "take\na\n",
                "line 1: the header needs the columns `take` and `person`",
            ),
            (
                "take,person\na.bvh,x\na.bvh,y\n",
                "line 3: a.bvh is listed again (first on line 2)",
            ),
            ("take,person\na.bvh,\n", "line 2: no person for a.bvh"),
            (
                "take,person\na.bvh,x,y\n",
                "line 2: 3 fields where the header has 2",
            ),
        ] {
            std::fs::write(&path, text).unwrap();
            let e = PersonMap::read(&path).unwrap_err().to_string();
            assert!(e.contains(expected), "{expected}: {e}");
        }
        let e = PersonMap::read(&dir.path().join("none.csv")).unwrap_err();
        assert!(
            e.to_string().contains("cannot read the mapping file"),
            "{e}"
        );
    }

    #[test]
    fn segments_persons_come_first_under_auto_and_are_required_under_segments() {
        let root = Path::new("/data");
        let take = TakeAt::new(root, Path::new("64_26.bvh"));
        assert_eq!(
            PersonRule::Auto.who(take, Some("carol")).unwrap().person,
            "carol"
        );
        assert_eq!(
            PersonRule::Segments
                .who(take, Some("carol"))
                .unwrap()
                .person,
            "carol"
        );
        assert_eq!(
            PersonRule::Folder.who(take, Some("carol")).unwrap().person,
            "data"
        );
        let e = PersonRule::Segments.who(take, None).unwrap_err();
        assert!(matches!(e, WhoError::NoSegments { .. }), "{e}");
        assert!(e.to_string().contains("--segments FILE"), "{e}");
    }

    #[test]
    fn rules_are_recorded_as_spelled_and_prefix_is_file() {
        for (given, recorded) in [
            ("auto", "auto"),
            ("folder", "folder"),
            ("prefix", "file"),
            ("file", "file"),
            ("segments", "segments"),
            (r"regex:^(p\d+)/", r"regex:^(p\d+)/"),
        ] {
            let rule: PersonRule = given.parse().unwrap();
            assert_eq!(rule.to_string(), recorded);
            assert_eq!(recorded.parse::<PersonRule>().unwrap(), rule);
        }
        assert_eq!(PersonRule::default(), PersonRule::Auto);
    }

    #[test]
    fn a_capture_s_guessed_person_is_its_performer_or_its_folder() {
        assert_eq!(guess_person(Path::new("/data/p01/r01.bvh")), "p01");
        assert_eq!(guess_person(Path::new("/data/cmu/64_26.bvh")), "64");
        assert_eq!(
            guess_person(Path::new("/d/x/dataset-1_bow_active_001.bvh")),
            "active"
        );
    }
}
