//! Reading and writing rotor TOML files: text into a [`RotorSpec`] (with the line of each
//! entry, to place validation errors), then [`RotorBuilder::build`](crate::RotorBuilder::build).

use crate::builder::{Entry, RotorBuilder, SitedError};
use crate::error::RotorError;
use crate::model::Rotor;
use crate::spec::RotorSpec;
use serde::de::{MapAccess, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer};
use std::path::Path;

impl Rotor {
    /// Reads and validates a rotor from TOML text (schema: `docs/rotor-model.md`).
    ///
    /// Syntax errors, unknown keys, missing keys and wrong types come back as
    /// [`RotorError::Parse`] with the 1-based line and column; physically invalid values as the
    /// other [`RotorError`] variants wrapped in [`RotorError::Located`] with the line of the entry
    /// or key at fault.
    pub fn from_toml_str(text: &str) -> Result<Self, RotorError> {
        build(text, None)
    }

    /// Reads and validates a rotor from a TOML file; every error names the file, and parse and
    /// validation errors the line.
    pub fn from_toml_file(path: impl AsRef<Path>) -> Result<Self, RotorError> {
        let path = path.as_ref();
        let io = |message: String| RotorError::Io { path: path.to_path_buf(), message };
        let bytes = std::fs::read(path).map_err(|e| io(e.to_string()))?;
        let text = String::from_utf8(bytes).map_err(|e| {
            // Say where the first bad byte is: a binary file, or text saved in another encoding.
            let valid = &e.as_bytes()[..e.utf8_error().valid_up_to()];
            let (line, column) = line_column(std::str::from_utf8(valid).unwrap_or_default(), valid.len());
            io(format!("not a UTF-8 text file (invalid byte at line {line}, column {column})"))
        })?;
        let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
        build(text, Some(path))
    }

    /// Writes the rotor as TOML: the description it was built from, with bearing names filled in.
    /// [`from_toml_str`](Self::from_toml_str) reads it back to an equal rotor.
    pub fn to_toml_string(&self) -> Result<String, RotorError> {
        toml::to_string(&self.spec).map_err(|e| RotorError::Serialize(e.to_string()))
    }
}

impl RotorSpec {
    /// Parses TOML text into an unchecked description (no physical validation).
    pub fn from_toml_str(text: &str) -> Result<Self, RotorError> {
        parse(text, None).map(|b| b.spec().clone())
    }
}

/// Most tables of one kind (`[[bearing]]`, `[[material]]`, …) a rotor file may have. A real rotor
/// has a few of each (a turbine-generator train some twenty bearings); a file with more is made
/// by mistake, and refused before the TOML is parsed (10⁵ bearings took seconds to parse).
pub const MAX_TABLES: usize = 10_000;

/// Refuses more than [`MAX_TABLES`] `[[kind]]` headers of one kind, naming the line of the first
/// one too many: a count of header lines, far cheaper than the parse it saves.
fn check_table_counts(text: &str, path: Option<&Path>) -> Result<(), RotorError> {
    let mut counts: Vec<(&str, usize)> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let Some(rest) = line.trim_start().strip_prefix("[[") else { continue };
        let Some((name, _)) = rest.split_once("]]") else { continue };
        let name = name.trim();
        let count = match counts.iter_mut().find(|(n, _)| *n == name) {
            Some((_, c)) => c,
            None => {
                counts.push((name, 0));
                &mut counts.last_mut().expect("just pushed").1
            }
        };
        *count += 1;
        if *count > MAX_TABLES {
            return Err(RotorError::Located {
                path: path.map(Path::to_path_buf),
                line: i + 1,
                error: Box::new(RotorError::TooManyTables { table: name.to_string(), max: MAX_TABLES }),
            });
        }
    }
    Ok(())
}

/// Parses and validates `text`; a validation error gets the line of the entry or key at fault.
fn build(text: &str, path: Option<&Path>) -> Result<Rotor, RotorError> {
    parse(text, path)?.build_sited().map_err(|SitedError { error, site }| {
        let line = site.and_then(|site| {
            // The text parsed as a `RotorSpec`, so it parses as a tree too; if not, no line.
            let root = toml::from_str::<Node>(text).ok()?;
            let table = match site.entry {
                Entry::Material(i) => root.get("material")?.item(i)?,
                Entry::Shaft => root.get("shaft")?,
                Entry::Section(i) => root.get("shaft")?.get("section")?.item(i)?,
                Entry::Disk(i) => root.get("disk")?.item(i)?,
                Entry::Bearing(i) => root.get("bearing")?.item(i)?,
                Entry::PointMass(i) => root.get("point_mass")?.item(i)?,
                Entry::Effect(i) => root.get("effect")?.item(i)?,
            };
            // The item of an array value, the key, or the entry itself (when the key is left at
            // its default, such as a bearing's name): the first of these the file places.
            let (key, value) =
                site.key.and_then(|k| table.entry(k)).map_or((None, None), |(k, v)| (Some(k), Some(v)));
            let item = value.zip(site.item).and_then(|(v, i)| v.item(i));
            let offset = item.and_then(|n| n.start).or(key.and_then(|k| k.start)).or(table.start);
            // An implicit table (`shaft.length = …`) has no start: its first key has.
            let first_key = || match &table.tree {
                Tree::Table(entries) => entries.first().and_then(|(k, _)| k.start),
                _ => None,
            };
            let offset = offset.or_else(first_key)?;
            Some(line_column(text, offset).0)
        });
        match line {
            Some(line) => {
                RotorError::Located { path: path.map(Path::to_path_buf), line, error: Box::new(error) }
            }
            None => error,
        }
    })
}

/// A TOML value and the byte offset it starts at, where the parser knows it: an implicit table
/// (made by a dotted key `shaft.length = …` or a header `[a.b]` without `[a]`) has none. Read
/// only to place a validation error.
struct Node {
    start: Option<usize>,
    tree: Tree,
}

/// A key and the byte offset it starts at.
struct Key {
    name: String,
    start: Option<usize>,
}

/// The shape of a TOML value.
enum Tree {
    /// A string, number, boolean or date.
    Leaf,
    /// An array (of values or of tables).
    Array(Vec<Node>),
    /// A table, keys in file order.
    Table(Vec<(Key, Node)>),
}

impl Node {
    /// The key `key` and its value, if this is a table that has it.
    fn entry(&self, key: &str) -> Option<(&Key, &Node)> {
        match &self.tree {
            Tree::Table(entries) => entries.iter().find(|(k, _)| k.name == key).map(|(k, v)| (k, v)),
            _ => None,
        }
    }

    /// The value of `key`, if this is a table that has it.
    fn get(&self, key: &str) -> Option<&Node> {
        self.entry(key).map(|(_, v)| v)
    }

    /// Item `i`, if this is an array that long.
    fn item(&self, i: usize) -> Option<&Node> {
        match &self.tree {
            Tree::Array(items) => items.get(i),
            _ => None,
        }
    }
}

// `toml` hands out spans through `toml::Spanned`'s serde protocol: a value deserialized as the
// struct named `SPANNED` with these fields comes as a map of them, if the parser knows its span,
// and as the plain value otherwise. `Spanned` itself fails on the latter; `Node` and `Key` accept
// both.
const SPANNED: &str = "$__serde_spanned_private_Spanned";
const START: &str = "$__serde_spanned_private_start";
const END: &str = "$__serde_spanned_private_end";
const VALUE: &str = "$__serde_spanned_private_value";
const FIELDS: &[&str] = &[START, END, VALUE];

/// Reads the rest of a span map whose first key, `START`, has been read: (start, value).
fn spanned<'de, A: MapAccess<'de>, T: Deserialize<'de>>(mut map: A) -> Result<(usize, T), A::Error> {
    let start: usize = map.next_value()?;
    let (mut value, mut end_seen) = (None, false);
    while let Some(key) = map.next_key::<String>()? {
        match key.as_str() {
            END if !end_seen => {
                map.next_value::<usize>()?;
                end_seen = true;
            }
            VALUE if value.is_none() => value = Some(map.next_value()?),
            _ => return Err(serde::de::Error::custom("unexpected key in a span")),
        }
    }
    let value = value.ok_or_else(|| serde::de::Error::missing_field(VALUE))?;
    Ok((start, value))
}

impl<'de> Deserialize<'de> for Key {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct KeyVisitor;

        impl<'de> Visitor<'de> for KeyVisitor {
            type Value = Key;

            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a TOML key")
            }

            fn visit_str<E>(self, name: &str) -> Result<Key, E> {
                Ok(Key { name: name.to_string(), start: None })
            }

            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Key, A::Error> {
                match map.next_key::<String>()?.as_deref() {
                    Some(START) => spanned(map).map(|(start, name)| Key { name, start: Some(start) }),
                    _ => Err(serde::de::Error::custom("a key that is a table")),
                }
            }
        }

        deserializer.deserialize_struct(SPANNED, FIELDS, KeyVisitor)
    }
}

/// Visits a value: with its span (a map of `START`, `END`, `VALUE`) when `spans`, else plain.
struct NodeVisitor {
    spans: bool,
}

impl<'de> Visitor<'de> for NodeVisitor {
    type Value = Node;

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a TOML value")
    }

    fn visit_bool<E>(self, _: bool) -> Result<Node, E> {
        Ok(Node { start: None, tree: Tree::Leaf })
    }

    fn visit_i64<E>(self, _: i64) -> Result<Node, E> {
        Ok(Node { start: None, tree: Tree::Leaf })
    }

    fn visit_u64<E>(self, _: u64) -> Result<Node, E> {
        Ok(Node { start: None, tree: Tree::Leaf })
    }

    fn visit_f64<E>(self, _: f64) -> Result<Node, E> {
        Ok(Node { start: None, tree: Tree::Leaf })
    }

    fn visit_str<E>(self, _: &str) -> Result<Node, E> {
        Ok(Node { start: None, tree: Tree::Leaf })
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Node, A::Error> {
        let mut items = Vec::new();
        while let Some(item) = seq.next_element()? {
            items.push(item);
        }
        Ok(Node { start: None, tree: Tree::Array(items) })
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Node, A::Error> {
        let Some(first) = map.next_key::<Key>()? else {
            return Ok(Node { start: None, tree: Tree::Table(Vec::new()) });
        };
        if self.spans && first.start.is_none() && first.name == START {
            let (start, Plain(node)) = spanned(map)?;
            return Ok(Node { start: Some(start), tree: node.tree });
        }
        let mut entries = vec![(first, map.next_value()?)];
        while let Some(key) = map.next_key()? {
            entries.push((key, map.next_value()?));
        }
        Ok(Node { start: None, tree: Tree::Table(entries) })
    }
}

impl<'de> Deserialize<'de> for Node {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_struct(SPANNED, FIELDS, NodeVisitor { spans: true })
    }
}

/// The value inside a span map (asking for its span again would recurse).
struct Plain(Node);

impl<'de> Deserialize<'de> for Plain {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(NodeVisitor { spans: false }).map(Plain)
    }
}

fn parse(text: &str, path: Option<&Path>) -> Result<RotorBuilder, RotorError> {
    check_table_counts(text, path)?;
    match toml::from_str::<RotorSpec>(text) {
        Ok(spec) => Ok(RotorBuilder::from_spec(spec)),
        Err(e) => {
            let path = path.map(Path::to_path_buf);
            // Serde lists the valid keys; the one most likely meant is named too.
            let message = eigenfit_core::names::with_serde_hint(e.message().trim_end());
            Err(match e.span() {
                Some(span) => {
                    let (line, column) = line_column(text, span.start);
                    RotorError::Parse { path, line, column, message }
                }
                None => RotorError::ParseUnplaced { path, message },
            })
        }
    }
}

/// Converts a byte offset in `text` to a 1-based (line, column in characters).
pub(crate) fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = text.get(..offset).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let column = before[line_start..].chars().count() + 1;
    (line, column)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_offsets_become_lines_and_columns() {
        let text = "a = 1\nbé = 2\n";
        assert_eq!(line_column(text, 0), (1, 1));
        assert_eq!(line_column(text, 6), (2, 1));
        // 'é' is two bytes but one column.
        assert_eq!(line_column(text, 9), (2, 3));
        assert_eq!(line_column(text, 1000), (3, 1));
    }

    #[test]
    fn more_tables_of_a_kind_than_any_rotor_has_are_refused_at_the_first_too_many() {
        let table = "[[ bearing ]] # a support\nnode = 0\nstiffness = 1e6\n";
        let text = format!("[shaft]\nlength = 1.0\nelements = 4\n{}", table.repeat(MAX_TABLES + 1));
        let err = Rotor::from_toml_str(&text).unwrap_err();
        // The header of bearing MAX_TABLES + 1: three lines of shaft, three per bearing.
        let line = 3 + 3 * MAX_TABLES + 1;
        assert_eq!(
            err.to_string(),
            format!("line {line}: more than {MAX_TABLES} [[bearing]] tables: a real rotor has a few; refused before parsing the file")
        );
        // Many tables of different kinds are each within the limit.
        let mixed = "[[material]]\nname = \"m\"\n".repeat(MAX_TABLES) + &table.repeat(3);
        assert!(check_table_counts(&mixed, None).is_ok());
    }
}
