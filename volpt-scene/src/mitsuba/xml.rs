//! A small XML element tree that remembers where each element was written.
//!
//! Mitsuba scene files carry all values in attributes, so the tree keeps only tags, attributes and
//! children. Each element records its file and line so that any later error can point at it, even
//! for elements that came from an `<include>`d file.

use std::path::Path;
use std::rc::Rc;

use quick_xml::events::{BytesStart, Event};
use quick_xml::Reader;

use crate::error::SceneError;

/// Deeper nesting than any scene needs; the limit keeps recursive passes off the stack's end.
const MAX_DEPTH: usize = 256;

#[derive(Clone, Debug)]
pub(crate) struct Element {
    pub tag: String,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<Element>,
    /// The file the element was written in.
    pub file: Rc<Path>,
    /// 1-based line of the element's `<`.
    pub line: usize,
}

impl Element {
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    /// How messages refer to the element: its tag and identifying attributes, e.g.
    /// `<float name="g">` or `<bsdf type="roughdielectric" id="glass">`.
    pub fn describe(&self) -> String {
        let mut s = format!("<{}", self.tag);
        for key in ["type", "name", "id"] {
            if let Some(value) = self.attr(key) {
                s.push_str(&format!(" {key}=\"{value}\""));
            }
        }
        s.push('>');
        s
    }

    /// The directory relative file names inside this element are resolved against.
    pub fn dir(&self) -> &Path {
        self.file.parent().unwrap_or(Path::new(""))
    }
}

/// Reads and parses an XML file into its root element.
pub(crate) fn parse_file(path: &Path) -> Result<Element, SceneError> {
    let bytes = crate::limits::read_file(path)?;
    let text = match std::str::from_utf8(&bytes) {
        Ok(text) => text,
        Err(e) => {
            let line = 1 + bytes[..e.valid_up_to()]
                .iter()
                .filter(|&&b| b == b'\n')
                .count();
            return Err(SceneError::Xml {
                path: path.to_path_buf(),
                line,
                message: "the file is not valid UTF-8".into(),
            });
        }
    };
    parse_str(text, Rc::from(path))
}

/// Parses XML text; `file` is recorded on every element and used in messages.
pub(crate) fn parse_str(text: &str, file: Rc<Path>) -> Result<Element, SceneError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let lines = LineIndex::new(text);
    let xml_error = |pos: u64, message: String| SceneError::Xml {
        path: file.to_path_buf(),
        line: lines.line_of(pos),
        message,
    };

    let mut reader = Reader::from_str(text);
    let mut stack: Vec<Element> = Vec::new();
    let mut root: Option<Element> = None;
    loop {
        // Whitespace is reported as text, so this is the offset of the next event's first byte.
        let start = reader.buffer_position();
        let event = reader
            .read_event()
            .map_err(|e| xml_error(reader.error_position(), e.to_string()))?;
        let finished = match event {
            Event::Start(e) => {
                if stack.len() >= MAX_DEPTH {
                    return Err(xml_error(
                        start,
                        format!("elements nested more than {MAX_DEPTH} deep"),
                    ));
                }
                stack.push(
                    element(&e, &file, lines.line_of(start)).map_err(|m| xml_error(start, m))?,
                );
                None
            }
            Event::Empty(e) => {
                Some(element(&e, &file, lines.line_of(start)).map_err(|m| xml_error(start, m))?)
            }
            // quick-xml has already checked that the end tag matches.
            Event::End(_) => stack.pop(),
            Event::Text(t) => {
                if !t.iter().all(u8::is_ascii_whitespace) {
                    let snippet: String = String::from_utf8_lossy(&t)
                        .trim()
                        .chars()
                        .take(40)
                        .collect();
                    return Err(xml_error(
                        start,
                        format!(
                            "unexpected text \"{snippet}\" (Mitsuba elements carry their values in \
                             attributes)"
                        ),
                    ));
                }
                None
            }
            Event::CData(_) => {
                return Err(xml_error(start, "unexpected CDATA section".into()));
            }
            Event::Eof => break,
            // Declarations, comments, processing instructions, doctypes carry nothing for us.
            _ => None,
        };
        if let Some(el) = finished {
            match stack.last_mut() {
                Some(parent) => parent.children.push(el),
                None if root.is_none() => root = Some(el),
                None => {
                    return Err(xml_error(
                        start,
                        format!("a second root element <{}> after the first", el.tag),
                    ))
                }
            }
        }
    }
    if let Some(open) = stack.last() {
        return Err(SceneError::Xml {
            path: file.to_path_buf(),
            line: lines.line_of(text.len() as u64),
            message: format!(
                "the file ends inside <{}> opened at line {}",
                open.tag, open.line
            ),
        });
    }
    root.ok_or_else(|| SceneError::Xml {
        path: file.to_path_buf(),
        line: 1,
        message: "the file holds no element".into(),
    })
}

fn element(e: &BytesStart<'_>, file: &Rc<Path>, line: usize) -> Result<Element, String> {
    let tag = std::str::from_utf8(e.name().as_ref())
        .map_err(|_| "a tag name that is not UTF-8".to_string())?
        .to_string();
    let mut attrs = Vec::new();
    for attr in e.attributes() {
        let attr = attr.map_err(|err| format!("<{tag}>: {err}"))?;
        let key = std::str::from_utf8(attr.key.as_ref())
            .map_err(|_| format!("<{tag}>: an attribute name that is not UTF-8"))?
            .to_string();
        let value = attr
            .unescape_value()
            .map_err(|err| format!("<{tag} {key}>: {err}"))?
            .into_owned();
        attrs.push((key, value));
    }
    Ok(Element {
        tag,
        attrs,
        children: Vec::new(),
        file: Rc::clone(file),
        line,
    })
}

/// Maps byte offsets to 1-based line numbers.
struct LineIndex {
    newlines: Vec<usize>,
}

impl LineIndex {
    fn new(text: &str) -> Self {
        Self {
            newlines: text
                .bytes()
                .enumerate()
                .filter(|&(_, b)| b == b'\n')
                .map(|(i, _)| i)
                .collect(),
        }
    }

    fn line_of(&self, offset: u64) -> usize {
        let offset = usize::try_from(offset).unwrap_or(usize::MAX);
        1 + self.newlines.partition_point(|&n| n < offset)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Element, SceneError> {
        parse_str(text, Rc::from(Path::new("t.xml")))
    }

    #[test]
    fn records_lines_and_attributes() {
        let root = parse("<?xml version=\"1.0\"?>\n<scene version=\"3.0.0\">\n  <!-- c -->\n  <float name=\"g\" value=\"0.5\"/>\n  <bsdf type=\"null\">\n  </bsdf>\n</scene>\n").unwrap();
        assert_eq!(root.tag, "scene");
        assert_eq!(root.line, 2);
        assert_eq!(root.children.len(), 2);
        assert_eq!(root.children[0].line, 4);
        assert_eq!(root.children[0].describe(), "<float name=\"g\">");
        assert_eq!(root.children[1].line, 5);
        assert_eq!(root.children[1].attr("type"), Some("null"));
    }

    #[test]
    fn reports_line_of_mismatched_end() {
        let err = parse("<scene>\n<a>\n</b>\n</scene>").unwrap_err();
        match err {
            SceneError::Xml { line, .. } => assert_eq!(line, 3),
            other => panic!("{other}"),
        }
    }

    #[test]
    fn rejects_unclosed_and_text() {
        assert!(parse("<scene>\n<a>\n").is_err());
        assert!(parse("<scene>hello</scene>").is_err());
        assert!(parse("").is_err());
        assert!(parse("<a/><b/>").is_err());
        assert!(parse("<a x=\"1\" x=\"2\"/>").is_err());
        assert!(parse(&"<a>".repeat(100_000)).is_err());
    }
}
