//! Reading a plugin's parameters (`<float name=...>`, nested objects, `<ref>`s) and noticing the
//! ones nobody read.
//!
//! Each builder wraps its element in a [`Plugin`], asks for the parameters it understands (under
//! every spelling Mitsuba has used for them: `maxDepth` and `max_depth` alike), then calls
//! [`Plugin::finish`]. Leftovers are handled there, uniformly: an unknown *property* (a
//! `<float>`, `<string>`...) only logs a warning, because it usually tunes something volpt has no
//! counterpart for; an unknown *object* (a `<texture>`, an `<emitter>` inside a shape...) or an
//! unknown tag is an error, because ignoring it would change what the scene means.

use std::cell::RefCell;
use std::collections::HashMap;

use super::preprocess::Dialect;
use super::xml::Element;
use crate::error::SceneError;

/// Tags that hold a single value.
const PROPERTY_TAGS: &[&str] = &[
    "float",
    "integer",
    "boolean",
    "string",
    "rgb",
    "srgb",
    "spectrum",
    "blackbody",
    "point",
    "vector",
    "transform",
];

/// Tags of Mitsuba objects (plugins), which may carry an `id` and be referenced.
pub(crate) const OBJECT_TAGS: &[&str] = &[
    "sensor",
    "film",
    "sampler",
    "rfilter",
    "integrator",
    "emitter",
    "shape",
    "bsdf",
    "medium",
    "phase",
    "volume",
    "texture",
    "subsurface",
];

/// What every builder shares: the dialect and the objects declared with an `id`.
pub(crate) struct Ctx<'a> {
    pub dialect: Dialect,
    ids: HashMap<&'a str, &'a Element>,
}

impl<'a> Ctx<'a> {
    pub fn new(root: &'a Element, dialect: Dialect) -> Result<Self, SceneError> {
        let mut ctx = Self {
            dialect,
            ids: HashMap::new(),
        };
        ctx.collect_ids(root)?;
        Ok(ctx)
    }

    fn collect_ids(&mut self, el: &'a Element) -> Result<(), SceneError> {
        for child in &el.children {
            if let (Some(id), true) = (child.attr("id"), OBJECT_TAGS.contains(&child.tag.as_str()))
            {
                if let Some(first) = self.ids.insert(id, child) {
                    return Err(invalid(
                        child,
                        &format!("{} with id=\"{id}\"", child.describe()),
                        "ids that are unique in the scene",
                        format!(
                            "a second object with this id (the first is at line {})",
                            first.line
                        ),
                    ));
                }
            }
            self.collect_ids(child)?;
        }
        Ok(())
    }

    /// The element a `<ref id>` points to; any other element is itself.
    pub fn resolve(&self, el: &'a Element) -> Result<&'a Element, SceneError> {
        if el.tag != "ref" {
            return Ok(el);
        }
        let id = el
            .attr("id")
            .ok_or_else(|| missing(el, "the id attribute"))?;
        self.ids.get(id).copied().ok_or_else(|| {
            invalid(
                el,
                &el.describe(),
                "the id of an object declared in the scene",
                format!("\"{id}\""),
            )
        })
    }
}

/// A parameter or nested object as written (`written`: the element or the `<ref>`) and as
/// resolved (`target`: the element holding the value).
#[derive(Clone, Copy)]
pub(crate) struct Arg<'a> {
    pub written: &'a Element,
    pub target: &'a Element,
}

impl<'a> Arg<'a> {
    /// The raw `value` attribute of the target, or a "missing" error.
    pub fn value(&self) -> Result<&'a str, SceneError> {
        self.target
            .attr("value")
            .ok_or_else(|| missing(self.target, "the value attribute"))
    }

    /// An error saying this parameter's value is not what was expected.
    pub fn invalid(&self, expected: &str, found: impl Into<String>) -> SceneError {
        invalid(self.target, &self.target.describe(), expected, found.into())
    }

    /// An error for a parameter whose element type is wrong (e.g. a `<texture>` where a number
    /// is needed).
    pub fn wrong_type(&self, expected: &str) -> SceneError {
        let found = match self.target.attr("type") {
            Some(t) => format!("<{} type=\"{t}\">", self.target.tag),
            None => format!("<{}>", self.target.tag),
        };
        invalid(self.written, &self.written.describe(), expected, found)
    }

    /// A finite number from `<float>` or `<integer>`.
    pub fn float(&self) -> Result<f32, SceneError> {
        if !matches!(self.target.tag.as_str(), "float" | "integer") {
            return Err(self.wrong_type("a <float>"));
        }
        let raw = self.value()?;
        parse_f32(raw).ok_or_else(|| self.invalid("a finite number", quoted(raw)))
    }

    pub fn integer(&self) -> Result<i64, SceneError> {
        if self.target.tag != "integer" {
            return Err(self.wrong_type("an <integer>"));
        }
        let raw = self.value()?;
        raw.trim()
            .parse()
            .map_err(|_| self.invalid("an integer", quoted(raw)))
    }

    pub fn boolean(&self) -> Result<bool, SceneError> {
        if self.target.tag != "boolean" {
            return Err(self.wrong_type("a <boolean>"));
        }
        let raw = self.value()?;
        match raw.trim().to_ascii_lowercase().as_str() {
            "true" => Ok(true),
            "false" => Ok(false),
            _ => Err(self.invalid("true or false", quoted(raw))),
        }
    }

    pub fn string(&self) -> Result<&'a str, SceneError> {
        if self.target.tag != "string" {
            return Err(self.wrong_type("a <string>"));
        }
        self.value()
    }

    /// A point or vector: `x`, `y`, `z` attributes or `value="x, y, z"`.
    pub fn point(&self) -> Result<[f64; 3], SceneError> {
        if !matches!(self.target.tag.as_str(), "point" | "vector") {
            return Err(self.wrong_type("a <point>"));
        }
        xyz(self.target, 0.0)
    }
}

/// A plugin element under construction; see the module documentation.
pub(crate) struct Plugin<'a> {
    pub el: &'a Element,
    pub ctx: &'a Ctx<'a>,
    used: RefCell<Vec<bool>>,
}

impl<'a> Plugin<'a> {
    pub fn new(el: &'a Element, ctx: &'a Ctx<'a>) -> Self {
        Self {
            el,
            ctx,
            used: RefCell::new(vec![false; el.children.len()]),
        }
    }

    /// The plugin's `type` attribute.
    pub fn kind(&self) -> Result<&'a str, SceneError> {
        self.el
            .attr("type")
            .ok_or_else(|| missing(self.el, "the type attribute"))
    }

    /// The parameter called by any of `names`; an error if it is given more than once.
    pub fn find(&self, names: &[&str]) -> Result<Option<Arg<'a>>, SceneError> {
        let found = self.take(|c| c.attr("name").is_some_and(|n| names.contains(&n)))?;
        match found.as_slice() {
            [] => Ok(None),
            [one] => Ok(Some(*one)),
            [first, second, ..] => Err(invalid(
                second.written,
                &second.written.describe(),
                "each parameter given once",
                format!(
                    "a second value for it (the first is at line {})",
                    first.written.line
                ),
            )),
        }
    }

    /// Nested objects with the given tag (inline or by `<ref>`), whatever their names.
    pub fn objects(&self, tag: &str) -> Result<Vec<Arg<'a>>, SceneError> {
        // A `<ref>` is claimed only if it points to this tag, so a wrong reference is reported
        // as unused rather than swallowed.
        let ctx = self.ctx;
        let mut out = Vec::new();
        let mut used = self.used.borrow_mut();
        for (i, child) in self.el.children.iter().enumerate() {
            if used[i] || (child.tag != tag && child.tag != "ref") {
                continue;
            }
            let target = ctx.resolve(child)?;
            if target.tag == tag {
                used[i] = true;
                out.push(Arg {
                    written: child,
                    target,
                });
            }
        }
        Ok(out)
    }

    /// At most one nested object with the given tag.
    pub fn object(&self, tag: &str) -> Result<Option<Arg<'a>>, SceneError> {
        let objects = self.objects(tag)?;
        if let [_, second, ..] = objects.as_slice() {
            return Err(SceneError::Unsupported {
                path: second.written.file.to_path_buf(),
                line: second.written.line,
                what: format!("a second <{tag}> in {}", self.el.describe()),
                reason: format!("volpt takes one <{tag}> here"),
            });
        }
        Ok(objects.into_iter().next())
    }

    /// Accepts parameters volpt has no use for but which do not change the image, silently.
    pub fn ignore(&self, names: &[&str]) {
        let mut used = self.used.borrow_mut();
        for (i, child) in self.el.children.iter().enumerate() {
            if child.attr("name").is_some_and(|n| names.contains(&n)) {
                used[i] = true;
            }
        }
    }

    /// Reads a string setting of Mitsuba's that volpt has no choice of: `accepted` (in any case,
    /// spaces around it aside) silently, any other value with a warning that says where it is and
    /// what volpt `uses` instead.
    pub fn warn_unless(
        &self,
        names: &[&str],
        accepted: &str,
        uses: &str,
    ) -> Result<(), SceneError> {
        if let Some(arg) = self.find(names)? {
            let raw = arg.string()?;
            if !raw.trim().eq_ignore_ascii_case(accepted) {
                tracing::warn!(
                    "{}:{}: {} value {}: volpt uses {uses}",
                    arg.target.file.display(),
                    arg.target.line,
                    arg.target.describe(),
                    quoted(raw)
                );
            }
        }
        Ok(())
    }

    /// Reports what was not read: properties with a warning, anything else as an error.
    pub fn finish(self) -> Result<(), SceneError> {
        let used = self.used.into_inner();
        for (child, _) in self.el.children.iter().zip(used).filter(|(_, used)| !used) {
            let tag = child.tag.as_str();
            if PROPERTY_TAGS.contains(&tag) {
                tracing::warn!(
                    "{}:{}: {} is not used by volpt's {} and is ignored",
                    child.file.display(),
                    child.line,
                    child.describe(),
                    self.el.describe()
                );
                continue;
            }
            let reason = if tag == "ref" {
                let target = self.ctx.resolve(child)?;
                format!(
                    "it refers to {}, which has no place inside {}",
                    target.describe(),
                    self.el.describe()
                )
            } else if OBJECT_TAGS.contains(&tag) {
                format!("volpt has no use for it inside {}", self.el.describe())
            } else {
                "not a Mitsuba element volpt knows".to_string()
            };
            return Err(SceneError::Unsupported {
                path: child.file.to_path_buf(),
                line: child.line,
                what: child.describe(),
                reason,
            });
        }
        Ok(())
    }

    /// An "unsupported" error about this plugin.
    pub fn unsupported(&self, reason: impl Into<String>) -> SceneError {
        SceneError::Unsupported {
            path: self.el.file.to_path_buf(),
            line: self.el.line,
            what: self.el.describe(),
            reason: reason.into(),
        }
    }

    /// A "missing" error about this plugin.
    pub fn missing(&self, what: impl Into<String>) -> SceneError {
        missing(self.el, &what.into())
    }

    fn take(&self, matches: impl Fn(&Element) -> bool) -> Result<Vec<Arg<'a>>, SceneError> {
        let mut out = Vec::new();
        let mut used = self.used.borrow_mut();
        for (i, child) in self.el.children.iter().enumerate() {
            if matches(child) {
                used[i] = true;
                out.push(Arg {
                    written: child,
                    target: self.ctx.resolve(child)?,
                });
            }
        }
        Ok(out)
    }
}

/// Reads `x`, `y`, `z` attributes (each defaulting to `default`) or `value="x, y, z"`.
pub(crate) fn xyz(el: &Element, default: f64) -> Result<[f64; 3], SceneError> {
    if let Some(raw) = el.attr("value") {
        if ["x", "y", "z"].iter().any(|k| el.attr(k).is_some()) {
            return Err(invalid(
                el,
                &el.describe(),
                "either value=\"x, y, z\" or x/y/z attributes",
                "both".into(),
            ));
        }
        return match numbers(raw).as_deref() {
            Some(&[x, y, z]) => Ok([x, y, z]),
            _ => Err(invalid(
                el,
                &format!("{} value", el.describe()),
                "three numbers",
                quoted(raw),
            )),
        };
    }
    let mut out = [default; 3];
    for (slot, key) in out.iter_mut().zip(["x", "y", "z"]) {
        if let Some(raw) = el.attr(key) {
            *slot = parse_f64(raw).ok_or_else(|| {
                invalid(
                    el,
                    &format!("{} {key}", el.describe()),
                    "a finite number",
                    quoted(raw),
                )
            })?;
        }
    }
    Ok(out)
}

/// Finite numbers separated by commas and/or whitespace, as Mitsuba writes lists.
pub(crate) fn numbers(raw: &str) -> Option<Vec<f64>> {
    raw.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|s| !s.is_empty())
        .map(parse_f64)
        .collect()
}

pub(crate) fn parse_f64(raw: &str) -> Option<f64> {
    raw.trim().parse::<f64>().ok().filter(|v| v.is_finite())
}

pub(crate) fn parse_f32(raw: &str) -> Option<f32> {
    parse_f64(raw).map(|v| v as f32).filter(|v| v.is_finite())
}

/// A literal as messages show it.
pub(crate) fn quoted(raw: &str) -> String {
    format!("\"{raw}\"")
}

pub(crate) fn invalid(el: &Element, field: &str, expected: &str, found: String) -> SceneError {
    SceneError::InvalidValue {
        path: el.file.to_path_buf(),
        line: el.line,
        field: field.to_string(),
        expected: expected.to_string(),
        found,
    }
}

pub(crate) fn missing(el: &Element, what: &str) -> SceneError {
    SceneError::Missing {
        path: el.file.to_path_buf(),
        line: el.line,
        element: el.describe(),
        what: what.to_string(),
    }
}
