//! The textual layer of a Mitsuba scene: `<default>`, `$name` substitution and `<include>`.
//!
//! Like Mitsuba, this walks the document in order: a `<default name value>` defines `name` unless
//! it is already defined (parameters given by the caller, `-D name=value`, win), and every
//! attribute value written after it may use `$name`. `<include filename>` splices the children of
//! the included file's `<scene>` in place. What comes out is a tree with neither.

use std::cell::Cell;
use std::path::{Path, PathBuf};

use super::xml::{parse_file, Element};
use crate::error::SceneError;
use crate::limits::{MAX_EXPANDED_XML_BYTES, MAX_INCLUDES};

/// Which generation of Mitsuba the scene was written for (from `<scene version="...">`). It
/// decides the meaning of a few things, notably where a grid's samples sit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Dialect {
    /// Mitsuba 0.5 / 0.6 (`version="0.x.y"`).
    Mitsuba06,
    /// Mitsuba 2 and 3 (`version="2.x.y"` / `"3.x.y"`).
    Mitsuba3,
}

/// Include depth beyond which we assume a mistake rather than a real scene.
const MAX_INCLUDE_DEPTH: usize = 32;

/// A scene tree with defaults, parameters and includes resolved.
pub(crate) struct Document {
    pub root: Element,
    pub dialect: Dialect,
}

/// Loads `path`, applying `params` (name, value) over the file's `<default>`s.
pub(crate) fn load(path: &Path, params: &[(String, String)]) -> Result<Document, SceneError> {
    let root = parse_file(path)?;
    let dialect = scene_dialect(&root)?;
    let mut state = State {
        params: params.iter().map(|(k, v)| Param::new(k, v, true)).collect(),
        include_stack: vec![canonical(path)],
        includes: 0,
        expanded_bytes: Cell::new(0),
    };
    let mut root = substitute(root, &state)?;
    let children = std::mem::take(&mut root.children);
    root.children = state.expand_all(children, dialect)?;
    for p in state
        .params
        .iter()
        .filter(|p| p.from_caller && !p.used.get())
    {
        tracing::warn!(
            "{}: parameter {}={} was given but the scene never uses ${}",
            path.display(),
            p.name,
            p.value,
            p.name
        );
    }
    Ok(Document { root, dialect })
}

struct Param {
    name: String,
    value: String,
    from_caller: bool,
    used: Cell<bool>,
}

impl Param {
    fn new(name: &str, value: &str, from_caller: bool) -> Self {
        Self {
            name: name.into(),
            value: value.into(),
            from_caller,
            used: Cell::new(false),
        }
    }
}

struct State {
    params: Vec<Param>,
    /// Canonical paths of the files being expanded, to refuse include cycles.
    include_stack: Vec<PathBuf>,
    /// `<include>`s expanded so far, repeats counted ([`MAX_INCLUDES`]).
    includes: usize,
    /// What the scene has expanded to so far ([`MAX_EXPANDED_XML_BYTES`]): attribute values after
    /// substitution plus [`ELEMENT_BYTES`] per element.
    expanded_bytes: Cell<u64>,
}

/// What one element counts for in the expansion budget besides its attribute values.
const ELEMENT_BYTES: u64 = 64;

impl State {
    /// Expands the children of a `<scene>`: handles `<default>` and `<include>`, substitutes
    /// parameters everywhere else.
    fn expand_all(
        &mut self,
        children: Vec<Element>,
        dialect: Dialect,
    ) -> Result<Vec<Element>, SceneError> {
        let mut out = Vec::with_capacity(children.len());
        for child in children {
            let child = substitute(child, self)?;
            match child.tag.as_str() {
                "default" => self.define_default(&child)?,
                "include" => out.extend(self.include(&child, dialect)?),
                _ => {
                    let child = substitute_descendants(child, self)?;
                    out.push(child);
                }
            }
        }
        Ok(out)
    }

    fn define_default(&mut self, el: &Element) -> Result<(), SceneError> {
        let name = required_attr(el, "name")?;
        let value = required_attr(el, "value")?;
        if !self.params.iter().any(|p| p.name == name) {
            self.params.push(Param::new(name, value, false));
        }
        Ok(())
    }

    fn include(&mut self, el: &Element, dialect: Dialect) -> Result<Vec<Element>, SceneError> {
        let filename = required_attr(el, "filename")?;
        let path = el.dir().join(filename);
        let key = canonical(&path);
        if self.include_stack.contains(&key) {
            return Err(SceneError::Unsupported {
                path: el.file.to_path_buf(),
                line: el.line,
                what: format!("<include filename=\"{filename}\">"),
                reason: format!(
                    "{} includes itself (directly or through other files)",
                    path.display()
                ),
            });
        }
        self.includes += 1;
        if self.includes > MAX_INCLUDES {
            return Err(SceneError::Unsupported {
                path: el.file.to_path_buf(),
                line: el.line,
                what: format!("<include filename=\"{filename}\">"),
                reason: format!(
                    "the scene expands more than {MAX_INCLUDES} includes (files that include \
                     other files several times multiply)"
                ),
            });
        }
        if self.include_stack.len() > MAX_INCLUDE_DEPTH {
            return Err(SceneError::Unsupported {
                path: el.file.to_path_buf(),
                line: el.line,
                what: format!("<include filename=\"{filename}\">"),
                reason: format!("includes nested more than {MAX_INCLUDE_DEPTH} deep"),
            });
        }
        let referenced = |error| SceneError::Referenced {
            path: el.file.to_path_buf(),
            line: el.line,
            element: format!("<include filename=\"{filename}\">"),
            error: Box::new(error),
        };
        let root = parse_file(&path).map_err(referenced)?;
        let included_dialect = scene_dialect(&root).map_err(referenced)?;
        if included_dialect != dialect {
            tracing::warn!(
                "{}:{}: {} was written for {:?} but the including scene for {:?}; volpt reads it \
                 with the including scene's conventions",
                el.file.display(),
                el.line,
                path.display(),
                included_dialect,
                dialect
            );
        }
        self.include_stack.push(key);
        let expanded = self.expand_all(root.children, dialect);
        self.include_stack.pop();
        expanded
    }

    /// Counts `bytes` more of expanded scene; an error about `el` past the budget.
    fn charge(&self, el: &Element, bytes: u64) -> Result<(), SceneError> {
        let total = self.expanded_bytes.get().saturating_add(bytes);
        self.expanded_bytes.set(total);
        if total > MAX_EXPANDED_XML_BYTES {
            return Err(SceneError::Unsupported {
                path: el.file.to_path_buf(),
                line: el.line,
                what: el.describe(),
                reason: format!(
                    "the scene expands to more than {MAX_EXPANDED_XML_BYTES} bytes (parameters \
                     whose values repeat other parameters, or includes that repeat includes, \
                     multiply)"
                ),
            });
        }
        Ok(())
    }

    fn lookup(&self, name: &str) -> Option<&str> {
        let p = self.params.iter().find(|p| p.name == name)?;
        p.used.set(true);
        Some(&p.value)
    }
}

fn substitute_descendants(mut el: Element, state: &State) -> Result<Element, SceneError> {
    let children = std::mem::take(&mut el.children);
    el.children = children
        .into_iter()
        .map(|c| substitute(c, state).and_then(|c| substitute_descendants(c, state)))
        .collect::<Result<_, _>>()?;
    Ok(el)
}

/// Replaces `$name` in the element's own attribute values. A name is the longest run of
/// `[A-Za-z0-9_]` after the `$` (Mitsuba replaces plain substrings, which makes `$a` clobber
/// `$ab`; the longest match is what users mean). A `$` not followed by a name is kept as is.
fn substitute(mut el: Element, state: &State) -> Result<Element, SceneError> {
    state.charge(&el, ELEMENT_BYTES)?;
    for i in 0..el.attrs.len() {
        if !el.attrs[i].1.contains('$') {
            state.charge(&el, el.attrs[i].1.len() as u64)?;
            continue;
        }
        let value = &el.attrs[i].1;
        let mut out = String::with_capacity(value.len());
        let mut rest = value.as_str();
        while let Some(pos) = rest.find('$') {
            out.push_str(&rest[..pos]);
            let after = &rest[pos + 1..];
            let len = after
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(after.len());
            let name = &after[..len];
            if name.is_empty() {
                out.push('$');
            } else {
                let Some(v) = state.lookup(name) else {
                    return Err(SceneError::Missing {
                        path: el.file.to_path_buf(),
                        line: el.line,
                        element: el.describe(),
                        what: format!(
                            "a value for ${name} (declare <default name=\"{name}\" value=\"...\"/> \
                             before this element, or pass -D {name}=...)"
                        ),
                    });
                };
                // Charged before it is copied, so no value outgrows the budget.
                state.charge(&el, v.len() as u64)?;
                out.push_str(v);
            }
            rest = &after[len..];
        }
        out.push_str(rest);
        el.attrs[i].1 = out;
    }
    Ok(el)
}

/// Checks the root is `<scene version="...">` and reads its dialect.
fn scene_dialect(root: &Element) -> Result<Dialect, SceneError> {
    if root.tag != "scene" {
        return Err(SceneError::InvalidValue {
            path: root.file.to_path_buf(),
            line: root.line,
            field: "root element".into(),
            expected: "<scene version=\"...\">".into(),
            found: format!("<{}>", root.tag),
        });
    }
    let version = root.attr("version").ok_or_else(|| SceneError::Missing {
        path: root.file.to_path_buf(),
        line: root.line,
        element: "<scene>".into(),
        what: "the version attribute (e.g. version=\"0.6.0\" or version=\"3.0.0\")".into(),
    })?;
    let major = version
        .split('.')
        .next()
        .and_then(|m| m.trim().parse::<u32>().ok());
    match major {
        Some(0) => Ok(Dialect::Mitsuba06),
        Some(2..) => Ok(Dialect::Mitsuba3),
        _ => Err(SceneError::InvalidValue {
            path: root.file.to_path_buf(),
            line: root.line,
            field: "<scene version>".into(),
            expected: "a Mitsuba 0.x, 2.x or 3.x version such as \"0.6.0\" or \"3.0.0\"".into(),
            found: format!("\"{version}\""),
        }),
    }
}

fn required_attr<'e>(el: &'e Element, name: &str) -> Result<&'e str, SceneError> {
    el.attr(name).ok_or_else(|| SceneError::Missing {
        path: el.file.to_path_buf(),
        line: el.line,
        element: el.describe(),
        what: format!("the {name} attribute"),
    })
}

/// A path's identity for cycle detection; a file that cannot be canonicalized fails later to open.
fn canonical(path: &Path) -> PathBuf {
    path.canonicalize().unwrap_or_else(|_| path.to_path_buf())
}
