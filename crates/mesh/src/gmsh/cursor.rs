//! A cursor over the bytes of an MSH 4.1 file that reads its values in either encoding: as
//! whitespace-separated ASCII tokens (spaces, tabs, CR and LF alike), or as the binary ints,
//! `size_t`s and doubles of the `$MeshFormat` line's data size and the byte order that the int 1
//! after that line shows.

/// How the sections' values are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Encoding {
    /// ASCII tokens.
    Ascii,
    /// Binary values: little or big endian, `size_t` of 4 or 8 bytes.
    Binary {
        /// Little-endian.
        little: bool,
        /// Bytes of a `size_t`.
        size_t: usize,
    },
}

/// A position in the file, with the encoding of its sections.
pub(super) struct Cursor<'a> {
    bytes: &'a [u8],
    at: usize,
    pub(super) encoding: Encoding,
    /// The section being read, for messages.
    pub(super) section: &'static str,
}

pub(super) type Result<T> = std::result::Result<T, String>;

fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\r' | b'\n' | 0x0b | 0x0c)
}

impl<'a> Cursor<'a> {
    pub(super) fn new(bytes: &'a [u8]) -> Self {
        Cursor {
            bytes,
            at: 0,
            encoding: Encoding::Ascii,
            section: "the file",
        }
    }

    /// Bytes not read yet.
    pub(super) fn remaining(&self) -> usize {
        self.bytes.len() - self.at
    }

    /// A capacity for `count` items of at least `item_bytes` bytes each that the rest of the
    /// file can hold: an untrusted count never sizes an allocation beyond the data.
    pub(super) fn capacity(&self, count: u64, item_bytes: usize) -> usize {
        let fits = self.remaining() / item_bytes.max(1);
        usize::try_from(count).map_or(fits, |c| c.min(fits))
    }

    fn skip_space(&mut self) {
        while self.at < self.bytes.len() && is_space(self.bytes[self.at]) {
            self.at += 1;
        }
    }

    /// Whether only whitespace is left.
    pub(super) fn at_end(&mut self) -> bool {
        self.skip_space();
        self.at >= self.bytes.len()
    }

    /// The next ASCII token (whatever the encoding: section markers are text).
    pub(super) fn token(&mut self, what: &str) -> Result<&'a str> {
        self.skip_space();
        let start = self.at;
        while self.at < self.bytes.len() && !is_space(self.bytes[self.at]) {
            self.at += 1;
        }
        if start == self.at {
            return Err(format!("{}: {what} is missing (the file ends)", self.section));
        }
        std::str::from_utf8(&self.bytes[start..self.at]).map_err(|_| format!("{}: {what} is not text", self.section))
    }

    /// The rest of the current line, without its line end (CR LF or LF).
    pub(super) fn line(&mut self) -> Result<&'a str> {
        let start = self.at;
        while self.at < self.bytes.len() && self.bytes[self.at] != b'\n' {
            self.at += 1;
        }
        let end = if self.at > start && self.bytes[self.at - 1] == b'\r' {
            self.at - 1
        } else {
            self.at
        };
        if self.at < self.bytes.len() {
            self.at += 1;
        }
        std::str::from_utf8(&self.bytes[start..end]).map_err(|_| format!("{}: a line is not text", self.section))
    }

    /// Skips blank characters up to and with the end of the current line (what ends a text line
    /// before binary data).
    pub(super) fn end_of_line(&mut self) -> Result<()> {
        while self.at < self.bytes.len() && matches!(self.bytes[self.at], b' ' | b'\t' | b'\r') {
            self.at += 1;
        }
        match self.bytes.get(self.at) {
            Some(b'\n') => {
                self.at += 1;
                Ok(())
            }
            _ => Err(format!(
                "{}: the line does not end before its binary data",
                self.section
            )),
        }
    }

    /// `n` raw bytes.
    pub(super) fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8]> {
        let end = self
            .at
            .checked_add(n)
            .filter(|&e| e <= self.bytes.len())
            .ok_or_else(|| format!("{}: {what} is cut short (the file ends)", self.section))?;
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }

    fn word<const N: usize>(&mut self, little: bool, what: &str) -> Result<[u8; N]> {
        let mut a: [u8; N] = self
            .take(N, what)?
            .try_into()
            .map_err(|_| format!("{what}: short read"))?;
        if !little {
            a.reverse();
        }
        Ok(a)
    }

    /// An `int` (a tag, a dimension, an element type).
    pub(super) fn int(&mut self, what: &str) -> Result<i32> {
        match self.encoding {
            Encoding::Ascii => {
                let t = self.token(what)?;
                t.parse()
                    .map_err(|_| format!("{}: {what} `{t}` is not a whole number", self.section))
            }
            Encoding::Binary { little, .. } => Ok(i32::from_le_bytes(self.word::<4>(little, what)?)),
        }
    }

    /// A `size_t` (a count, a node or element tag).
    pub(super) fn size(&mut self, what: &str) -> Result<u64> {
        match self.encoding {
            Encoding::Ascii => {
                let t = self.token(what)?;
                t.parse()
                    .map_err(|_| format!("{}: {what} `{t}` is not a whole number", self.section))
            }
            Encoding::Binary { little, size_t: 8 } => Ok(u64::from_le_bytes(self.word::<8>(little, what)?)),
            Encoding::Binary { little, .. } => Ok(u64::from(u32::from_le_bytes(self.word::<4>(little, what)?))),
        }
    }

    /// A `double` (a coordinate).
    pub(super) fn float(&mut self, what: &str) -> Result<f64> {
        match self.encoding {
            Encoding::Ascii => {
                let t = self.token(what)?;
                t.parse()
                    .map_err(|_| format!("{}: {what} `{t}` is not a number", self.section))
            }
            Encoding::Binary { little, .. } => Ok(f64::from_le_bytes(self.word::<8>(little, what)?)),
        }
    }

    /// Bytes of one value of each kind in this encoding, the least an item can take (ASCII: a
    /// digit and a separator).
    pub(super) fn least_bytes(&self) -> usize {
        match self.encoding {
            Encoding::Ascii => 2,
            Encoding::Binary { .. } => 4,
        }
    }

    /// Skips `n` ints, `size_t`s or doubles as `what` (by reading them: ASCII has no widths).
    pub(super) fn skip_floats(&mut self, n: usize, what: &str) -> Result<()> {
        match self.encoding {
            Encoding::Ascii => {
                for _ in 0..n {
                    self.float(what)?;
                }
                Ok(())
            }
            Encoding::Binary { .. } => self
                .take(n.checked_mul(8).ok_or("a count overflows")?, what)
                .map(|_| ()),
        }
    }

    /// Moves past `marker` (such as `$EndNodeData`), where the section is not read.
    pub(super) fn skip_past(&mut self, marker: &str) -> Result<()> {
        let needle = marker.as_bytes();
        let found = self.bytes[self.at..]
            .windows(needle.len())
            .position(|w| w == needle)
            .ok_or_else(|| format!("{}: no `{marker}`", self.section))?;
        self.at += found + needle.len();
        Ok(())
    }

    /// The section's end marker `$End<name>`, after its data.
    pub(super) fn expect_end(&mut self, name: &str) -> Result<()> {
        let t = self.token("the section's end")?;
        if t.strip_prefix("$End") == Some(name) {
            Ok(())
        } else {
            let shown: String = t.chars().take(40).collect();
            Err(format!(
                "{}: `$End{name}` expected, found `{shown}` (more data than the section's counts announce, or a count too small)",
                self.section
            ))
        }
    }
}
