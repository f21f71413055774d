//! Typed reading of a spanned TOML tree, with errors that name the file, the line and the
//! field. Every table declares the keys it knows, so a typo is an error listing the valid
//! keys rather than a silently ignored setting (pbrt's "unused parameter" rule).

use std::ops::Range;
use std::path::Path;

use raylab_core::{Rgb, Vec2, Vec3};
use toml::de::{DeTable, DeValue};
use toml::Spanned;

use crate::error::{shorten, LoadError};

/// A parsed document and what is needed to turn byte offsets into lines.
pub struct Doc<'s> {
    pub file: &'s Path,
    line_starts: Vec<usize>,
}

impl<'s> Doc<'s> {
    pub fn new(file: &'s Path, src: &str) -> Self {
        let line_starts = std::iter::once(0).chain(src.match_indices('\n').map(|(i, _)| i + 1)).collect();
        Self { file, line_starts }
    }

    pub fn line(&self, offset: usize) -> usize {
        self.line_starts.partition_point(|&s| s <= offset)
    }

    pub fn err(&self, span: &Range<usize>, field: &str, msg: impl Into<String>) -> LoadError {
        LoadError::new(self.file, Some(self.line(span.start)), field, msg)
    }

    /// Parses the document; a syntax error keeps the parser's message and position.
    pub fn parse<'i>(&self, src: &'i str) -> Result<Spanned<DeTable<'i>>, LoadError> {
        DeTable::parse(src).map_err(|e| {
            let line = e.span().map(|s| self.line(s.start));
            LoadError::new(self.file, line, "", format!("TOML syntax error: {}", e.message().trim_end()))
        })
    }
}

/// One value with its location.
#[derive(Clone)]
pub struct Val<'a, 'i> {
    pub doc: &'a Doc<'a>,
    pub field: String,
    pub value: &'a Spanned<DeValue<'i>>,
}

fn describe(v: &DeValue) -> String {
    match v {
        DeValue::String(_) => "a string".into(),
        DeValue::Integer(_) => "an integer".into(),
        DeValue::Float(_) => "a float".into(),
        DeValue::Boolean(_) => "a boolean".into(),
        DeValue::Datetime(_) => "a date".into(),
        DeValue::Array(a) => format!("an array of {} elements", a.len()),
        DeValue::Table(_) => "a table".into(),
    }
}

impl<'a, 'i> Val<'a, 'i> {
    pub fn span(&self) -> Range<usize> {
        self.value.span()
    }

    pub fn err(&self, msg: impl Into<String>) -> LoadError {
        self.doc.err(&self.span(), &self.field, msg)
    }

    fn expected(&self, what: &str) -> LoadError {
        self.err(format!("expected {what}, found {}", describe(self.value.get_ref())))
    }

    pub fn number(&self) -> Result<f64, LoadError> {
        let v = match self.value.get_ref() {
            DeValue::Integer(i) => i64::from_str_radix(&i.as_str().replace('_', ""), i.radix()).map(|v| v as f64).ok(),
            DeValue::Float(f) => f.as_str().replace('_', "").parse::<f64>().ok(),
            _ => return Err(self.expected("a number")),
        };
        match v {
            Some(v) if v.is_finite() => Ok(v),
            _ => Err(self.err("expected a finite number")),
        }
    }

    pub fn f32(&self) -> Result<f32, LoadError> {
        let v = self.number()?;
        if v.abs() > f32::MAX as f64 {
            return Err(self.err(format!("{v} is too large")));
        }
        Ok(v as f32)
    }

    pub fn integer(&self) -> Result<i64, LoadError> {
        match self.value.get_ref() {
            DeValue::Integer(i) => i64::from_str_radix(&i.as_str().replace('_', ""), i.radix()).map_err(|_| self.err("integer out of range")),
            _ => Err(self.expected("an integer")),
        }
    }

    pub fn str(&self) -> Result<&'a str, LoadError> {
        match self.value.get_ref() {
            DeValue::String(s) => Ok(s.as_ref()),
            _ => Err(self.expected("a string")),
        }
    }

    pub fn bool(&self) -> Result<bool, LoadError> {
        match self.value.get_ref() {
            DeValue::Boolean(b) => Ok(*b),
            _ => Err(self.expected("a boolean")),
        }
    }

    pub fn array(&self) -> Result<&'a [Spanned<DeValue<'i>>], LoadError> {
        match self.value.get_ref() {
            DeValue::Array(a) => Ok(&a[..]),
            _ => Err(self.expected("an array")),
        }
    }

    /// `[x, y, ...]` of exactly `N` numbers.
    pub fn floats<const N: usize>(&self) -> Result<[f32; N], LoadError> {
        let what = format!("an array of {N} numbers");
        let DeValue::Array(a) = self.value.get_ref() else { return Err(self.expected(&what)) };
        if a.len() != N {
            return Err(self.expected(&what));
        }
        let mut out = [0.0; N];
        for (k, e) in a.iter().enumerate() {
            if !matches!(e.get_ref(), DeValue::Integer(_) | DeValue::Float(_)) {
                return Err(self.err(format!("expected {what}, found {} at index {k}", describe(e.get_ref()))));
            }
            out[k] = Val { doc: self.doc, field: self.field.clone(), value: e }.f32()?;
        }
        Ok(out)
    }

    pub fn vec3(&self) -> Result<Vec3, LoadError> {
        self.floats::<3>().map(Vec3::from_array)
    }

    pub fn vec2(&self) -> Result<Vec2, LoadError> {
        self.floats::<2>().map(Vec2::from_array)
    }

    /// A colour: `[r, g, b]` or one number for grey; never negative.
    pub fn color(&self) -> Result<Rgb, LoadError> {
        let c = match self.value.get_ref() {
            DeValue::Integer(_) | DeValue::Float(_) => Rgb::splat(self.f32()?),
            DeValue::Array(_) => self.vec3()?,
            _ => return Err(self.expected("a colour (a number or an array of 3 numbers)")),
        };
        if c.min_element() < 0.0 {
            return Err(self.err(format!("colour components must not be negative, found [{}, {}, {}]", c.x, c.y, c.z)));
        }
        Ok(c)
    }

    /// An array of `[x, y, z]` points.
    pub fn points(&self) -> Result<Vec<Vec3>, LoadError> {
        let a = self.array()?;
        a.iter().map(|e| Val { doc: self.doc, field: self.field.clone(), value: e }.vec3()).collect()
    }

    pub fn table(&self, known: &'static [&'static str]) -> Result<Table<'a, 'i>, LoadError> {
        match self.value.get_ref() {
            DeValue::Table(t) => Table::new(self.doc, self.field.clone(), self.span(), t, known),
            _ => Err(self.expected("a table")),
        }
    }
}

/// A TOML table whose keys have been checked against the known ones.
pub struct Table<'a, 'i> {
    pub doc: &'a Doc<'a>,
    /// Dotted path of the table (`camera`, `shapes[2]`), empty at the top level.
    pub path: String,
    pub span: Range<usize>,
    map: &'a DeTable<'i>,
}

impl<'a, 'i> Table<'a, 'i> {
    pub fn new(doc: &'a Doc<'a>, path: String, span: Range<usize>, map: &'a DeTable<'i>, known: &'static [&'static str]) -> Result<Self, LoadError> {
        let t = Self { doc, path, span, map };
        for (k, _) in map.iter() {
            if !known.contains(&k.get_ref().as_ref()) {
                return Err(doc.err(&k.span(), &t.field(k.get_ref()), format!("unknown field (valid: {})", known.join(", "))));
            }
        }
        Ok(t)
    }

    pub fn field(&self, key: &str) -> String {
        if self.path.is_empty() {
            key.to_string()
        } else {
            format!("{}.{key}", self.path)
        }
    }

    /// The value of `key`, if present.
    pub fn get(&self, key: &str) -> Option<Val<'a, 'i>> {
        let value = self.map.iter().find(|(k, _)| k.get_ref() == key).map(|(_, v)| v)?;
        Some(Val { doc: self.doc, field: self.field(key), value })
    }

    pub fn has(&self, key: &str) -> bool {
        self.map.iter().any(|(k, _)| k.get_ref() == key)
    }

    pub fn req(&self, key: &str) -> Result<Val<'a, 'i>, LoadError> {
        self.get(key).ok_or_else(|| self.doc.err(&self.span, &self.field(key), "missing (required)"))
    }

    pub fn opt<T>(&self, key: &str, f: impl FnOnce(&Val<'a, 'i>) -> Result<T, LoadError>) -> Result<Option<T>, LoadError> {
        self.get(key).map(|v| f(&v)).transpose()
    }

    /// Sub-tables of an array of tables (`[[shapes]]`), each with its index in the path.
    pub fn tables(&self, key: &str, known: &'static [&'static str]) -> Result<Vec<Table<'a, 'i>>, LoadError> {
        let Some(v) = self.get(key) else { return Ok(Vec::new()) };
        let arr = v.array().map_err(|_| v.err("expected an array of tables ([[...]])"))?;
        arr.iter()
            .enumerate()
            .map(|(i, e)| {
                Val { doc: self.doc, field: format!("{}[{i}]", v.field), value: e }.table(known)
            })
            .collect()
    }

    /// The `type` key of a table, checked against the valid names.
    pub fn type_name(&self, valid: &[&str]) -> Result<&'a str, LoadError> {
        let v = self.req("type")?;
        let s = v.str()?;
        if valid.contains(&s) {
            Ok(s)
        } else {
            Err(v.err(format!("unknown type `{}` (valid: {})", shorten(s), valid.join(", "))))
        }
    }
}

/// Range checks of values, with the messages every field shares.
pub(crate) fn positive(v: &Val, x: f32) -> Result<f32, LoadError> {
    if x > 0.0 {
        Ok(x)
    } else {
        Err(v.err(format!("must be positive, found {x}")))
    }
}

pub(crate) fn in_range(v: &Val, x: i64, lo: i64, hi: i64) -> Result<i64, LoadError> {
    if (lo..=hi).contains(&x) {
        Ok(x)
    } else {
        Err(v.err(format!("must be between {lo} and {hi}, found {x}")))
    }
}

pub(crate) fn in_range_f32(v: &Val, x: f32, lo: f32, hi: f32) -> Result<f32, LoadError> {
    if (lo..=hi).contains(&x) {
        Ok(x)
    } else {
        Err(v.err(format!("must be between {lo} and {hi}, found {x}")))
    }
}
