//! The structure of an IGES 5.3 file in its fixed 80-column form: the Start (S), Global (G),
//! Directory Entry (D), Parameter Data (P) and Terminate (T) sections, the Global section's
//! delimiters, length unit and model scale, Hollerith strings, directory entries of two lines and
//! parameter data continued over lines. What the entities mean is the importer's
//! (`import/iges.rs`); this module only splits the file into entities with their parameters.
//!
//! Every error names its place as IGES does: the section letter and sequence number (`D 37`,
//! `P 112`, `T 1`) and, for an entity, its type.

use crate::spec::Units;
use crate::{Error, Result};
use std::collections::HashMap;

/// One parameter of an entity (or of the Global section).
#[derive(Clone, Debug, PartialEq)]
pub enum Param {
    /// A number (integer, real or pointer; `D` exponents read as `E`).
    Num(f64),
    /// A Hollerith string (`3HABC`).
    Str(String),
    /// An empty parameter (the default).
    Empty,
}

/// One entity: its directory entry and its parameters.
#[derive(Clone, Debug)]
pub struct Entity {
    /// The entity type number (110, 126, 144, …).
    pub kind: i64,
    /// The form number.
    pub form: i64,
    /// The sequence number of its first directory line (its pointer, `D 37`).
    pub de: usize,
    /// The sequence number of its first parameter line (`P 112`).
    pub p: usize,
    /// The directory pointer of its transformation matrix (entity 124), 0 when none.
    pub transform: usize,
    /// The subordinate entity switch of the status number (0: independent).
    pub subordinate: u32,
    /// The parameters after the type number, up to the record delimiter.
    pub params: Vec<Param>,
}

/// An IGES file split into entities.
#[derive(Clone, Debug)]
pub struct IgesFile {
    /// The length unit of the Global section's units flag (and name), when it is one of the
    /// design's units.
    pub units: Option<Units>,
    /// The unit's name as the file gives it (flag and name), for reports.
    pub unit_name: String,
    /// The model space scale (model units per real unit; 1 in almost every file).
    pub scale: f64,
    /// The entities in directory order.
    pub entities: Vec<Entity>,
    by_de: HashMap<usize, usize>,
}

impl IgesFile {
    /// The entity whose directory entry starts at sequence number `de`.
    pub fn get(&self, de: usize) -> Option<&Entity> {
        self.by_de.get(&de).map(|&k| &self.entities[k])
    }
}

/// A cursor over an entity's real parameters ([`Entity::reals_from`]).
pub struct Reals<'a> {
    entity: &'a Entity,
    at: usize,
}

impl Reals<'_> {
    /// The next `n` parameters as finite reals ([`Entity::real`], `what` naming them).
    pub fn take(&mut self, n: usize, what: &str) -> Result<Vec<f64>> {
        let v = (self.at..self.at + n)
            .map(|k| self.entity.real(k, what))
            .collect::<Result<Vec<f64>>>()?;
        self.at += n;
        Ok(v)
    }
}

impl Entity {
    /// `D 37, P 112: entity 126`: where an error about this entity is.
    pub fn place(&self) -> String {
        format!("D {}, P {}: entity {}", self.de, self.p, self.kind)
    }

    /// An error about this entity: one line with its place.
    pub fn bad(&self, what: &str) -> Error {
        Error::invalid(format!("{}: {what}", self.place()))
    }

    /// Parameter `k` (1-based, as the IGES specification counts them after the type number).
    fn param(&self, k: usize) -> Option<&Param> {
        k.checked_sub(1).and_then(|i| self.params.get(i))
    }

    /// Parameter `k` as a finite real number (an empty parameter is 0, the IGES default).
    pub fn real(&self, k: usize, what: &str) -> Result<f64> {
        match self.param(k) {
            Some(Param::Num(x)) if x.is_finite() => Ok(*x),
            Some(Param::Empty) => Ok(0.0),
            Some(Param::Num(_)) => {
                Err(self.bad(&format!("parameter {k} ({what}) is not a finite number")))
            }
            Some(Param::Str(_)) => {
                Err(self.bad(&format!("parameter {k} ({what}) is a string, not a number")))
            }
            None => Err(self.bad(&format!(
                "parameter {k} ({what}) is missing: the entity has {}",
                self.params.len()
            ))),
        }
    }

    /// The real parameters from `k` on, taken a run at a time ([`Reals::take`]).
    pub fn reals_from(&self, k: usize) -> Reals<'_> {
        Reals {
            entity: self,
            at: k,
        }
    }

    /// Parameter `k` as an integer in `lo..=hi`.
    pub fn int(&self, k: usize, what: &str, lo: i64, hi: i64) -> Result<i64> {
        let x = self.real(k, what)?;
        if x.fract() != 0.0 || x < lo as f64 || x > hi as f64 {
            return Err(self.bad(&format!(
                "parameter {k} ({what}) is {x}, not an integer from {lo} to {hi}"
            )));
        }
        Ok(x as i64)
    }

    /// Parameter `k` as a count that the entity's remaining parameters can hold, `per` each.
    pub fn count(&self, k: usize, what: &str, per: usize) -> Result<usize> {
        let room = self.params.len().saturating_sub(k) / per.max(1);
        Ok(self.int(k, what, 0, room as i64)? as usize)
    }

    /// Parameter `k` as a pointer to an entity of the file (0 allowed when `optional`).
    pub fn pointer(&self, file: &IgesFile, k: usize, what: &str, optional: bool) -> Result<usize> {
        let x = self.real(k, what)?;
        if x == 0.0 && optional {
            return Ok(0);
        }
        let d = x.abs();
        if x.fract() != 0.0 || d > usize::MAX as f64 || file.get(d as usize).is_none() {
            return Err(self.bad(&format!(
                "parameter {k} ({what}) points at D {x}, which is not an entity of the file"
            )));
        }
        Ok(d as usize)
    }
}

/// The 80-column lines of the file by section, each with its file line number.
struct Lines<'a> {
    by_section: HashMap<u8, Vec<(usize, &'a str)>>,
}

fn split_lines(text: &str) -> Result<Lines<'_>> {
    let mut by_section: HashMap<u8, Vec<(usize, &str)>> = HashMap::new();
    for (k, line) in text.lines().enumerate() {
        let line = line.trim_end_matches('\r');
        if line.trim().is_empty() {
            continue;
        }
        let b = line.as_bytes();
        if b.len() < 73 || !line.is_char_boundary(72) || !line.is_char_boundary(73) {
            // The last line of a file written without padding may be short: only T allowed.
            return Err(Error::invalid(format!(
                "line {}: not an 80-column IGES line (the section letter belongs in column 73)",
                k + 1
            )));
        }
        let section = b[72];
        match section {
            b'S' | b'G' | b'D' | b'P' | b'T' => {}
            b'F' | b'C' | b'B' => {
                return Err(Error::invalid(format!(
                    "line {}: a compressed or binary IGES file (section {}): only the fixed \
                     80-column ASCII form is read",
                    k + 1,
                    section as char
                )))
            }
            c => {
                return Err(Error::invalid(format!(
                    "line {}: `{}` in column 73 is not an IGES section letter (S, G, D, P, T)",
                    k + 1,
                    c as char
                )))
            }
        }
        by_section.entry(section).or_default().push((k + 1, line));
    }
    Ok(Lines { by_section })
}

/// The sequence number in columns 74–80 of a line.
fn sequence(line: &str) -> Option<usize> {
    line.get(73..).and_then(|s| s.trim().parse().ok())
}

/// Splits parameter text into parameters at `delim`, up to `end` (the record delimiter);
/// Hollerith strings (`nH…`) may hold either delimiter.
fn parameters(text: &str, delim: char, end: char) -> std::result::Result<Vec<Param>, String> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    loop {
        while i < chars.len() && chars[i] == ' ' {
            i += 1;
        }
        // A Hollerith string: digits, `H`, then exactly that many characters.
        let mut j = i;
        while j < chars.len() && chars[j].is_ascii_digit() {
            j += 1;
        }
        let param = if j > i && j < chars.len() && (chars[j] == 'H' || chars[j] == 'h') {
            let n: usize = chars[i..j]
                .iter()
                .collect::<String>()
                .parse()
                .map_err(|_| format!("parameter {}: a bad Hollerith count", out.len() + 1))?;
            let start = j + 1;
            if n > chars.len().saturating_sub(start) {
                return Err(format!(
                    "parameter {}: a Hollerith string of {n} characters runs past the data",
                    out.len() + 1
                ));
            }
            i = start + n;
            Param::Str(chars[start..start + n].iter().collect())
        } else {
            let start = i;
            while i < chars.len() && chars[i] != delim && chars[i] != end {
                i += 1;
            }
            let t: String = chars[start..i].iter().collect();
            let t = t.trim();
            if t.is_empty() {
                Param::Empty
            } else {
                let x: f64 = t
                    .replace(['D', 'd'], "E")
                    .parse()
                    .map_err(|_| format!("parameter {}: `{t}` is not a number", out.len() + 1))?;
                Param::Num(x)
            }
        };
        out.push(param);
        while i < chars.len() && chars[i] == ' ' {
            i += 1;
        }
        match chars.get(i) {
            Some(c) if *c == delim => i += 1,
            Some(c) if *c == end => return Ok(out),
            Some(c) => {
                return Err(format!(
                    "parameter {}: `{c}` where a delimiter (`{delim}` or `{end}`) belongs",
                    out.len()
                ))
            }
            None => {
                return Err(format!(
                    "the data ends after {} parameters without the record delimiter `{end}`",
                    out.len()
                ))
            }
        }
    }
}

/// The two delimiters at the start of the Global section (`1H,,1H;,` or defaults).
fn delimiters(g: &str) -> std::result::Result<(char, char, &str), String> {
    let mut rest = g.trim_start();
    let mut take = |default: char, which: &str, delim: Option<char>| {
        let d = if rest.starts_with("1H") || rest.starts_with("1h") {
            let c = rest[2..]
                .chars()
                .next()
                .ok_or_else(|| format!("the {which} delimiter is missing"))?;
            rest = &rest[2 + c.len_utf8()..];
            c
        } else {
            default
        };
        // The delimiter after this parameter: the parameter delimiter just read.
        let after = delim.unwrap_or(d);
        rest = rest.trim_start();
        match rest.strip_prefix(after) {
            Some(r) => rest = r,
            None => {
                return Err(format!(
                    "the {which} delimiter is not followed by `{after}`"
                ))
            }
        }
        Ok(d)
    };
    let p = take(',', "parameter", None)?;
    let r = take(';', "record", Some(p))?;
    if p == r || p == ' ' || r == ' ' {
        return Err("the parameter and record delimiters must differ and not be spaces".into());
    }
    Ok((p, r, rest))
}

/// The design's unit of the Global section's units flag (14) and name (15).
fn unit_of(flag: Option<f64>, name: Option<&str>) -> Option<Units> {
    let by_name = |n: &str| match n.trim().to_ascii_uppercase().as_str() {
        "MM" => Some(Units::Millimetre),
        "CM" => Some(Units::Centimetre),
        "M" => Some(Units::Metre),
        "IN" | "INCH" => Some(Units::Inch),
        _ => None,
    };
    match flag.map(|f| f as i64) {
        Some(1) => Some(Units::Inch),
        Some(2) => Some(Units::Millimetre),
        Some(6) => Some(Units::Metre),
        Some(10) => Some(Units::Centimetre),
        Some(3) => name.and_then(by_name),
        None => name.and_then(by_name),
        _ => None,
    }
}

/// Reads the structure of an IGES file: the Global section and every entity's directory entry
/// and parameters.
pub fn parse(text: &str) -> Result<IgesFile> {
    let lines = split_lines(text)?;
    let section = |c: u8| lines.by_section.get(&c).map_or(&[][..], Vec::as_slice);
    // The Terminate section: the line counts of the others, so a truncated file is found.
    let Some(&(tline, t)) = section(b'T').first() else {
        return Err(Error::invalid(
            "not a complete IGES file: no Terminate (T) section (a truncated file?)",
        ));
    };
    for (k, c) in [b'S', b'G', b'D', b'P'].iter().enumerate() {
        let field = t.get(8 * k + 1..8 * k + 8).map(str::trim);
        let said = field.and_then(|f| f.parse::<usize>().ok());
        let have = section(*c).len();
        match said {
            Some(n) if n == have => {}
            Some(n) => {
                return Err(Error::invalid(format!(
                    "T 1 (line {tline}): the file says {n} {} line(s), it has {have} (a \
                     truncated or edited file?)",
                    *c as char
                )))
            }
            None => {
                return Err(Error::invalid(format!(
                    "T 1 (line {tline}): the count of {} lines is not a number",
                    *c as char
                )))
            }
        }
    }
    // Sequence numbers run 1, 2, … in every section.
    for c in [b'S', b'G', b'D', b'P'] {
        for (k, (line, l)) in section(c).iter().enumerate() {
            if sequence(l) != Some(k + 1) {
                return Err(Error::invalid(format!(
                    "line {line}: the sequence number of {} {} is missing or out of order",
                    c as char,
                    k + 1
                )));
            }
        }
    }
    // Global section: columns 1–72.
    let g: String = section(b'G')
        .iter()
        .map(|(_, l)| l.get(..72).unwrap_or(l))
        .collect();
    let gbad = |m: String| Error::invalid(format!("G 1: the Global section: {m}"));
    let (delim, end, rest) = delimiters(&g).map_err(gbad)?;
    let global = parameters(rest, delim, end).map_err(gbad)?;
    // `global[k]` is Global parameter k + 3.
    let gnum = |k: usize| match global.get(k - 3) {
        Some(Param::Num(x)) => Some(*x),
        _ => None,
    };
    let gstr = |k: usize| match global.get(k - 3) {
        Some(Param::Str(s)) => Some(s.as_str()),
        _ => None,
    };
    let scale = match gnum(13) {
        None => 1.0,
        Some(s) if s.is_finite() && s > 0.0 => s,
        Some(s) => return Err(gbad(format!("the model space scale (13) is {s}"))),
    };
    let units = unit_of(gnum(14), gstr(15));
    let unit_name = format!(
        "flag {}{}",
        gnum(14).map_or("none".to_string(), |f| f.to_string()),
        gstr(15).map_or(String::new(), |s| format!(" ({s})"))
    );
    // Parameter data: columns 1–64 per line, by sequence number.
    let p_lines = section(b'P');
    // Directory entries: two lines each, eight-column fields.
    let d_lines = section(b'D');
    if d_lines.len() % 2 != 0 {
        return Err(Error::invalid(format!(
            "D {}: the Directory Entry section ends inside an entry (a truncated file?)",
            d_lines.len()
        )));
    }
    let mut entities = Vec::with_capacity(d_lines.len() / 2);
    let mut by_de = HashMap::new();
    for pair in d_lines.chunks(2) {
        let de = entities.len() * 2 + 1;
        let field = |line: &str, k: usize| -> Option<String> {
            line.get(8 * k..8 * k + 8).map(|f| f.trim().to_string())
        };
        let dbad = |m: String| Error::invalid(format!("D {de}: {m}"));
        let int = |line: &str, k: usize, what: &str| -> Result<i64> {
            let f = field(line, k).unwrap_or_default();
            if f.is_empty() {
                return Ok(0);
            }
            f.parse()
                .map_err(|_| dbad(format!("field {} ({what}) `{f}` is not an integer", k + 1)))
        };
        let (l1, l2) = (pair[0].1, pair[1].1);
        let kind = int(l1, 0, "entity type")?;
        if int(l2, 0, "entity type")? != kind {
            return Err(dbad(
                "the two lines of the entry give different entity types".into(),
            ));
        }
        let p = int(l1, 1, "parameter data pointer")?;
        let transform = int(l1, 6, "transformation matrix")?;
        let status = field(l1, 8).unwrap_or_default();
        let status = format!("{status:0>8}");
        let subordinate = status
            .get(2..4)
            .and_then(|s| s.trim().parse().ok())
            .unwrap_or(0);
        let count = int(l2, 3, "parameter line count")?;
        let form = int(l2, 4, "form number")?;
        if kind == 0 {
            // The null entity: no parameters.
            by_de.insert(de, entities.len());
            entities.push(Entity {
                kind,
                form,
                de,
                p: 0,
                transform: 0,
                subordinate,
                params: Vec::new(),
            });
            continue;
        }
        let (Ok(p), Ok(count)) = (usize::try_from(p), usize::try_from(count)) else {
            return Err(dbad(format!(
                "entity {kind}: a negative parameter pointer or line count"
            )));
        };
        if p == 0 || count == 0 || p - 1 + count > p_lines.len() {
            return Err(dbad(format!(
                "entity {kind}: its parameter lines P {p} to P {} are not in the file ({} P \
                 lines)",
                p + count.saturating_sub(1),
                p_lines.len()
            )));
        }
        let transform = usize::try_from(transform)
            .map_err(|_| dbad(format!("entity {kind}: a negative transformation pointer")))?;
        let mut body = String::new();
        for (k, (_, line)) in p_lines[p - 1..p - 1 + count].iter().enumerate() {
            let back: Option<usize> = line.get(64..72).and_then(|s| s.trim().parse().ok());
            if back != Some(de) {
                return Err(Error::invalid(format!(
                    "P {}: the line belongs to D {}, not to D {de} (entity {kind}) that points \
                     at it",
                    p + k,
                    back.map_or("?".to_string(), |b| b.to_string())
                )));
            }
            body.push_str(line.get(..64).unwrap_or(line));
        }
        let pbad = |m: String| Error::invalid(format!("D {de}, P {p}: entity {kind}: {m}"));
        let mut params = parameters(&body, delim, end).map_err(pbad)?;
        match params.first() {
            Some(Param::Num(t)) if *t == kind as f64 => {}
            _ => {
                return Err(pbad(
                    "the parameter data does not start with the entity's type".into(),
                ))
            }
        }
        params.remove(0);
        by_de.insert(de, entities.len());
        entities.push(Entity {
            kind,
            form,
            de,
            p,
            transform,
            subordinate,
            params,
        });
    }
    for e in &entities {
        if e.transform != 0 && file_kind(&entities, &by_de, e.transform) != Some(124) {
            return Err(Error::invalid(format!(
                "D {}: entity {}: its transformation matrix pointer D {} is not an entity 124",
                e.de, e.kind, e.transform
            )));
        }
    }
    Ok(IgesFile {
        units,
        unit_name,
        scale,
        entities,
        by_de,
    })
}

fn file_kind(entities: &[Entity], by_de: &HashMap<usize, usize>, de: usize) -> Option<i64> {
    by_de.get(&de).map(|&k| entities[k].kind)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parameters_split_at_delimiters_and_read_hollerith_strings() {
        let p = parameters("126,3H,;a,1.5D2, ,-2;comment", ',', ';').unwrap();
        assert_eq!(
            p,
            [
                Param::Num(126.0),
                Param::Str(",;a".into()),
                Param::Num(150.0),
                Param::Empty,
                Param::Num(-2.0)
            ]
        );
        assert!(parameters("1,2", ',', ';').unwrap_err().contains("record"));
        assert!(parameters("1,x;", ',', ';').unwrap_err().contains("`x`"));
        assert!(parameters("1,9Habc;", ',', ';')
            .unwrap_err()
            .contains("runs past"));
        let (d, r, rest) = delimiters("1H//1H#/7HPRODUCT#").unwrap();
        assert_eq!((d, r, rest), ('/', '#', "7HPRODUCT#"));
        let (d, r, _) = delimiters(",,7HPRODUCT;").unwrap();
        assert_eq!((d, r), (',', ';'));
    }
}
