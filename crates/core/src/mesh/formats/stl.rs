//! STL, binary and ASCII: a small reader of our own.
//!
//! Why not a crate: the maintained `stl_io` tells binary from ASCII by a leading `solid `,
//! but many CAD exporters write binary STL whose 80-byte header starts with `solid`, and its
//! binary reader is private, so that choice cannot be overridden. Here a file is binary when
//! its size is exactly `84 + 50 × count` (the count at bytes 80..84), else ASCII when it
//! starts with `solid` and is text (UTF-8, no NUL byte); any other file is binary STL whose
//! count does not match its size, refused before anything is allocated.
//!
//! Every facet contributes three vertices of its own (welding merges the bitwise-equal ones);
//! the facet normals and the 2-byte attribute are ignored (normals are computed from the faces).

use super::ReadMesh;

/// Header bytes before the triangle count.
const HEADER: usize = 80;
/// Bytes of one binary facet: normal, three vertices (12 × f32), attribute (u16).
const FACET: usize = 50;

pub(super) fn read(bytes: &[u8]) -> Result<ReadMesh, String> {
    if bytes.len() >= HEADER + 4 {
        let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        let expected = (HEADER as u64 + 4).saturating_add(count.saturating_mul(FACET as u64));
        if expected == bytes.len() as u64 {
            return read_binary(&bytes[HEADER + 4..]);
        }
        // Binary unless it reads as ASCII STL: a 'solid' header with text after it.
        let text = starts_with_solid(bytes) && !bytes.contains(&0) && std::str::from_utf8(bytes).is_ok();
        if !text {
            return Err(format!(
                "binary STL header declares {count} triangles ({expected} bytes), but the file has {} bytes",
                bytes.len()
            ));
        }
    }
    if !starts_with_solid(bytes) {
        return Err(format!("{} bytes: too short for binary STL and not ASCII STL (no 'solid')", bytes.len()));
    }
    read_ascii(bytes)
}

fn starts_with_solid(bytes: &[u8]) -> bool {
    let start = bytes.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(bytes.len());
    bytes[start..].starts_with(b"solid")
}

fn read_binary(facets: &[u8]) -> Result<ReadMesh, String> {
    let count = facets.len() / FACET;
    let mut mesh = ReadMesh { positions: Vec::with_capacity(count * 3), ..ReadMesh::default() };
    mesh.triangles.reserve(count);
    for (facet, record) in facets.chunks_exact(FACET).enumerate() {
        let float = |k: usize| {
            let at = 12 + 4 * k;
            f32::from_le_bytes([record[at], record[at + 1], record[at + 2], record[at + 3]])
        };
        for corner in 0..3 {
            let position = [float(3 * corner), float(3 * corner + 1), float(3 * corner + 2)];
            if !position.iter().all(|x| x.is_finite()) {
                return Err(format!("triangle {facet} has a non-finite coordinate {position:?}"));
            }
            mesh.positions.push(position);
        }
        let base = (3 * facet) as u32;
        mesh.triangles.push([base, base + 1, base + 2]);
    }
    Ok(mesh)
}

/// Whitespace-separated words with their 1-based line numbers.
struct Words<'a> {
    text: &'a str,
    line: usize,
}

impl<'a> Words<'a> {
    fn next(&mut self) -> Option<(&'a str, usize)> {
        loop {
            let trimmed = self.text.trim_start_matches(|c: char| c.is_ascii_whitespace() && c != '\n');
            if let Some(rest) = trimmed.strip_prefix('\n') {
                self.line += 1;
                self.text = rest;
                continue;
            }
            if trimmed.is_empty() {
                self.text = trimmed;
                return None;
            }
            let end = trimmed.find(|c: char| c.is_ascii_whitespace()).unwrap_or(trimmed.len());
            let (word, rest) = trimmed.split_at(end);
            self.text = rest;
            return Some((word, self.line));
        }
    }

    /// The next word, which must be `expected`.
    fn expect(&mut self, expected: &str) -> Result<(), String> {
        match self.next() {
            Some((word, _)) if word.eq_ignore_ascii_case(expected) => Ok(()),
            Some((word, line)) => Err(format!("line {line}: expected '{expected}', found '{word}'")),
            None => Err(format!("truncated: the file ends where '{expected}' should be (line {})", self.line)),
        }
    }

    /// The next word as a finite number.
    fn number(&mut self) -> Result<f32, String> {
        match self.next() {
            Some((word, line)) => match word.parse::<f32>() {
                Ok(value) if value.is_finite() => Ok(value),
                Ok(_) => Err(format!("line {line}: '{word}' is not a finite number")),
                Err(_) => Err(format!("line {line}: '{word}' is not a number")),
            },
            None => Err(format!("truncated: the file ends inside a facet (line {})", self.line)),
        }
    }

    /// Skips the rest of the current line (the solid's name).
    fn skip_line(&mut self) {
        match self.text.find('\n') {
            Some(end) => self.text = &self.text[end..],
            None => self.text = "",
        }
    }
}

fn read_ascii(bytes: &[u8]) -> Result<ReadMesh, String> {
    let text = std::str::from_utf8(bytes).map_err(|err| format!("ASCII STL that is not text: {err}"))?;
    let mut words = Words { text, line: 1 };
    words.expect("solid")?;
    words.skip_line();
    let mut mesh = ReadMesh::default();
    loop {
        match words.next() {
            Some((word, _)) if word.eq_ignore_ascii_case("endsolid") => break,
            Some((word, _)) if word.eq_ignore_ascii_case("facet") => {}
            Some((word, line)) => return Err(format!("line {line}: expected 'facet' or 'endsolid', found '{word}'")),
            None => return Err(format!("truncated: the file ends without 'endsolid' (line {})", words.line)),
        }
        words.expect("normal")?;
        for _ in 0..3 {
            words.number()?;
        }
        words.expect("outer")?;
        words.expect("loop")?;
        let base = u32::try_from(mesh.positions.len()).map_err(|_| "more than 2^32 vertices".to_owned())?;
        for _ in 0..3 {
            words.expect("vertex")?;
            mesh.positions.push([words.number()?, words.number()?, words.number()?]);
        }
        words.expect("endloop")?;
        words.expect("endfacet")?;
        mesh.triangles.push([base, base + 1, base + 2]);
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ascii_errors_name_the_line() {
        let text = "solid a b\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 x 0\n";
        let err = read(text.as_bytes()).unwrap_err();
        assert!(err.contains("line 5") && err.contains("'x'"), "{err}");
        let truncated = "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n";
        assert!(read(truncated.as_bytes()).unwrap_err().contains("truncated"));
    }

    #[test]
    fn binary_with_a_solid_header() {
        let mut bytes = b"solid but binary".to_vec();
        bytes.resize(80, b' ');
        bytes.extend(1u32.to_le_bytes());
        for value in [0.0f32, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
            bytes.extend(value.to_le_bytes());
        }
        bytes.extend([0, 0]);
        let mesh = read(&bytes).unwrap();
        assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
        assert_eq!(mesh.positions[2], [0.0, 1.0, 0.0]);
    }
}
