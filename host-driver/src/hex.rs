//! Hexadecimal input as people paste it: `010dd204`, `01 0d d2 04`, `01:0d:d2:04`, `0x010dd204`.

use thiserror::Error;

/// Why text is not a byte string in hex.
#[derive(Debug, Error, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum HexError {
    /// Nothing but separators.
    #[error("no hex digits")]
    Empty,
    /// A character that is neither a hex digit nor a separator.
    #[error("'{ch}' at position {position} is not a hex digit")]
    BadDigit {
        ch: char,
        /// Its position in the input, counting characters from 0.
        position: usize,
    },
    /// Bytes need two digits each.
    #[error("odd number of hex digits ({0}): each byte needs two")]
    OddLength(usize),
}

/// Parses hex digits into bytes, skipping whitespace, `:` and `-`, and an optional leading `0x`.
pub fn parse_hex(text: &str) -> Result<Vec<u8>, HexError> {
    let trimmed = text.trim_start();
    let (skip, body) = match trimmed.strip_prefix("0x").or_else(|| trimmed.strip_prefix("0X")) {
        Some(rest) => (text.len() - rest.len(), rest),
        None => (text.len() - trimmed.len(), trimmed),
    };
    let mut digits = Vec::with_capacity(body.len());
    for (i, ch) in body.chars().enumerate() {
        if ch.is_whitespace() || ch == ':' || ch == '-' {
            continue;
        }
        let position = text[..skip].chars().count() + i;
        digits.push(ch.to_digit(16).ok_or(HexError::BadDigit { ch, position })? as u8);
    }
    if digits.is_empty() {
        return Err(HexError::Empty);
    }
    if digits.len() % 2 != 0 {
        return Err(HexError::OddLength(digits.len()));
    }
    Ok(digits.chunks_exact(2).map(|d| (d[0] << 4) | d[1]).collect())
}

/// Formats bytes as lowercase hex without separators.
pub fn to_hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accepts_common_forms() {
        for text in ["010dd204", "01 0d d2 04", "01:0D:d2:04", "0x010dd204", "  01-0d\nd204 "] {
            assert_eq!(parse_hex(text), Ok(vec![0x01, 0x0d, 0xd2, 0x04]), "{text:?}");
        }
        assert_eq!(to_hex(&[0x01, 0xab]), "01ab");
    }

    #[test]
    fn rejects_with_a_reason() {
        assert_eq!(parse_hex(" : "), Err(HexError::Empty));
        assert_eq!(parse_hex("01 0g"), Err(HexError::BadDigit { ch: 'g', position: 4 }));
        assert_eq!(parse_hex("0x01z"), Err(HexError::BadDigit { ch: 'z', position: 4 }));
        assert_eq!(parse_hex("010"), Err(HexError::OddLength(3)));
    }
}
