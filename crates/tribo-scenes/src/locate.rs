//! Finds the line and column of a JSON path (`bodies[3].shapes[0].radius`) in a JSON text,
//! so that errors found after parsing (range checks, unknown material names) can point at
//! the place in the file. A small position-tracking scan of well-formed JSON; returns
//! `None` if the path is not in the text.

#[derive(Debug, PartialEq)]
enum Segment {
    Key(String),
    Index(usize),
}

fn split_path(path: &str) -> Vec<Segment> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let (key, mut rest) = match part.find('[') {
            Some(i) => (&part[..i], &part[i..]),
            None => (part, ""),
        };
        if !key.is_empty() {
            out.push(Segment::Key(key.to_string()));
        }
        while let Some(end) = rest.find(']') {
            if let Ok(i) = rest[1..end].parse() {
                out.push(Segment::Index(i));
            }
            rest = &rest[end + 1..];
        }
    }
    out
}

struct Scanner<'a> {
    s: &'a [u8],
    i: usize,
    line: usize,
    col: usize,
}

impl Scanner<'_> {
    fn bump(&mut self) -> Option<u8> {
        let c = *self.s.get(self.i)?;
        self.i += 1;
        if c == b'\n' {
            self.line += 1;
            self.col = 1;
        } else if c & 0xC0 != 0x80 {
            // Count characters, not UTF-8 continuation bytes.
            self.col += 1;
        }
        Some(c)
    }

    fn peek(&self) -> Option<u8> {
        self.s.get(self.i).copied()
    }

    fn ws(&mut self) {
        while matches!(self.peek(), Some(b' ' | b'\t' | b'\n' | b'\r')) {
            self.bump();
        }
    }

    fn string(&mut self) -> Option<String> {
        self.bump(); // opening quote
        let start = self.i;
        loop {
            match self.bump()? {
                b'\\' => {
                    self.bump()?;
                }
                b'"' => break,
                _ => {}
            }
        }
        String::from_utf8(self.s[start..self.i - 1].to_vec()).ok()
    }

    /// Scans one value; `depth` segments of `target` are matched so far.
    /// Depths past the target's length mean "inside a branch that does not match".
    fn value(&mut self, target: &[Segment], depth: usize) -> Option<Option<(usize, usize)>> {
        self.ws();
        if depth == target.len() {
            return Some(Some((self.line, self.col)));
        }
        match self.peek()? {
            b'{' => {
                self.bump();
                loop {
                    self.ws();
                    match self.peek()? {
                        b'}' => {
                            self.bump();
                            return Some(None);
                        }
                        b',' => {
                            self.bump();
                        }
                        b'"' => {
                            let pos = (self.line, self.col);
                            let key = self.string()?;
                            self.ws();
                            self.bump(); // ':'
                            let hit = depth < target.len() && matches!(&target[depth], Segment::Key(k) if *k == key);
                            if hit && depth + 1 == target.len() {
                                // Point at the key: "radius": -1 reads best from the key.
                                return Some(Some(pos));
                            }
                            if let Some(found) = self.value(target, if hit { depth + 1 } else { usize::MAX / 2 })? {
                                return Some(Some(found));
                            }
                        }
                        _ => return None,
                    }
                }
            }
            b'[' => {
                self.bump();
                let mut index = 0;
                loop {
                    self.ws();
                    match self.peek()? {
                        b']' => {
                            self.bump();
                            return Some(None);
                        }
                        b',' => {
                            self.bump();
                            index += 1;
                        }
                        _ => {
                            let hit =
                                depth < target.len() && matches!(&target[depth], Segment::Index(i) if *i == index);
                            if let Some(found) = self.value(target, if hit { depth + 1 } else { usize::MAX / 2 })? {
                                return Some(Some(found));
                            }
                        }
                    }
                }
            }
            b'"' => {
                self.string()?;
                Some(None)
            }
            _ => {
                while let Some(c) = self.peek() {
                    if matches!(c, b',' | b'}' | b']' | b' ' | b'\n' | b'\r' | b'\t') {
                        break;
                    }
                    self.bump();
                }
                Some(None)
            }
        }
    }
}

/// Line and column (1-based) of the value (or key) at `path` in `text`.
pub fn locate_path(text: &str, path: &str) -> Option<(usize, usize)> {
    let target = split_path(path);
    let mut sc = Scanner {
        s: text.as_bytes(),
        i: 0,
        line: 1,
        col: 1,
    };
    if target.is_empty() {
        return Some((1, 1));
    }
    sc.value(&target, 0).flatten()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_nested_paths() {
        let text = "{\n  \"bodies\": [\n    {\"name\": \"a\"},\n    {\"shapes\": [ {\"radius\": -1} ]}\n  ]\n}";
        assert_eq!(locate_path(text, "bodies[1].shapes[0].radius"), Some((4, 19)));
        assert_eq!(locate_path(text, "bodies[0].name"), Some((3, 6)));
        assert_eq!(locate_path(text, "bodies[2]"), None);
        assert_eq!(locate_path(text, "nothing"), None);
    }

    #[test]
    fn map_keys() {
        let text = "{\"materials\": {\"wood\": {\"friction\": 0.5}}}";
        assert_eq!(locate_path(text, "materials.wood.friction"), Some((1, 25)));
    }
}
