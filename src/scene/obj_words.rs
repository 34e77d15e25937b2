//! The words of an OBJ line and the indices of a face corner, read from bytes where that gives the same answers
//! as the standard library's `str::split_whitespace` and `str::parse::<i64>` with fewer instructions (the line
//! reader, `super::obj`, spends most of its time here).

/// An index as `str::parse::<i64>` reads it (an optional sign, then decimal digits, within i64), from bytes.
pub(super) fn parse_index(bytes: &[u8]) -> Option<i64> {
    let (negative, digits) = match bytes.split_first() {
        Some((b'-', rest)) => (true, rest),
        Some((b'+', rest)) => (false, rest),
        _ => (false, bytes),
    };
    if digits.is_empty() {
        return None;
    }
    // Summed below zero, where i64 reaches one further (−2⁶³).
    let mut value: i64 = 0;
    for &b in digits {
        let digit = b.wrapping_sub(b'0');
        if digit > 9 {
            return None;
        }
        value = value.checked_mul(10)?.checked_sub(i64::from(digit))?;
    }
    if negative { Some(value) } else { value.checked_neg() }
}

/// The words of a line, as `str::split_whitespace` gives them; where the line is ASCII, found byte by byte
/// (Unicode's white space among ASCII characters: tab, line feed, vertical tab, form feed, carriage return, space).
pub(super) enum Words<'a> {
    Ascii(&'a str),
    Unicode(std::str::SplitWhitespace<'a>),
}

impl<'a> Words<'a> {
    pub(super) fn of(line: &'a str) -> Self {
        if line.is_ascii() { Words::Ascii(line) } else { Words::Unicode(line.split_whitespace()) }
    }
}

impl<'a> Iterator for Words<'a> {
    type Item = &'a str;

    fn next(&mut self) -> Option<&'a str> {
        match self {
            Words::Unicode(words) => words.next(),
            Words::Ascii(rest) => {
                let space = |b: &u8| *b == b' ' || (b'\t'..=b'\r').contains(b);
                let bytes = rest.as_bytes();
                let Some(start) = bytes.iter().position(|b| !space(b)) else {
                    *rest = "";
                    return None;
                };
                let end = bytes[start..].iter().position(space).map_or(bytes.len(), |len| start + len);
                let word = &rest[start..end];
                *rest = &rest[end..];
                Some(word)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indices_and_words_are_read_as_the_standard_library_reads_them() {
        let indices = [
            "0",
            "7",
            "-7",
            "+7",
            "007",
            "-0",
            "+",
            "-",
            "",
            "1a",
            " 1",
            "1 ",
            "--1",
            "+-1",
            "9223372036854775807",
            "9223372036854775808",
            "-9223372036854775808",
            "-9223372036854775809",
            "99999999999999999999",
            "١",
        ];
        for text in indices {
            assert_eq!(parse_index(text.as_bytes()), text.parse::<i64>().ok(), "{text:?}");
        }
        let lines = ["", " ", "v 1 2 3", "\tf  1/2/3\x0b4//5\x0c6\r", "  g a b  ", "usemtl\u{a0}red x", "f 1\u{3000}2"];
        for line in lines {
            assert_eq!(Words::of(line).collect::<Vec<_>>(), line.split_whitespace().collect::<Vec<_>>(), "{line:?}");
        }
    }
}
