//! A small, seeded, deterministic mutator for the stable runner (libFuzzer brings its own).
//!
//! Each mutant is 1 to 4 stacked edits of one file of an input (or, one time in sixteen, of
//! the whole multi-file input, so that headers and names change too):
//!
//! - flip 1 to 4 bits; set a byte to a random value;
//! - insert 1 to 16 random bytes, or a run of one byte; delete a range;
//! - write an interesting integer (0, 1, -1, 2^7, 2^15, 2^31, 2^32 - 1, 2^63, ...) in 1, 2, 4
//!   or 8 bytes, little or big endian, over or into the bytes;
//! - replace a decimal number of the text by a huge, negative, tiny, infinite or NaN-like one;
//! - truncate; splice in a range of another input of the corpus; copy a range elsewhere, up to
//!   64 times (repeated structure: many faces, deep nesting);
//! - insert or write a token of the format's dictionary.
//!
//! The mutants of one seed are the same on every machine (ChaCha8).

use crate::files::{self, Part};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Mutants are cut to this size.
pub const MAX_INPUT: usize = 256 * 1024;

/// Integers at the edges of the usual widths.
const INTERESTING: &[u64] = &[
    0,
    1,
    2,
    0x7f,
    0x80,
    0xff,
    0x100,
    0x7fff,
    0x8000,
    0xffff,
    0x1_0000,
    0x7fff_ffff,
    0x8000_0000,
    0xffff_ffff,
    0x1_0000_0000,
    0x7fff_ffff_ffff_ffff,
    0x8000_0000_0000_0000,
    u64::MAX,
    u64::MAX - 1,
];

/// Numbers that replace a number of a text format.
const NUMBERS: &[&str] = &[
    "0",
    "-0",
    "1",
    "-1",
    "0.5",
    "255",
    "65535",
    "65536",
    "2147483647",
    "2147483648",
    "-2147483649",
    "4294967295",
    "4294967296",
    "9007199254740993",
    "18446744073709551615",
    "18446744073709551616",
    "100000000",
    "3.4028236e38",
    "1e308",
    "-1e308",
    "1e999",
    "1e-320",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "Infinity",
];

/// A seeded mutator.
pub struct Mutator {
    rng: ChaCha8Rng,
}

impl Mutator {
    /// A mutator whose mutants depend only on `seed`.
    pub fn new(seed: u64) -> Self {
        Self {
            rng: ChaCha8Rng::seed_from_u64(seed),
        }
    }

    /// A random index below `n` (which must be positive).
    pub fn below(&mut self, n: usize) -> usize {
        self.rng.random_range(0..n)
    }

    /// A mutant of `input`; `other` is another input of the corpus (for splicing),
    /// `multi_file` says whether inputs are several files ([`files`]), `words` are the format's
    /// tokens.
    pub fn mutate(
        &mut self,
        input: &[u8],
        other: &[u8],
        multi_file: bool,
        words: &[&str],
    ) -> Vec<u8> {
        let mut out = if multi_file && self.below(16) != 0 {
            let mut parts = files::split(input);
            let i = self.below(parts.len());
            let others = files::split(other);
            let partner = others
                .iter()
                .find(|p| p.name == parts[i].name)
                .unwrap_or(&others[0])
                .bytes
                .clone();
            let edits = 1 + self.below(4);
            for _ in 0..edits {
                let bytes = std::mem::take(&mut parts[i].bytes);
                parts[i] = Part {
                    name: parts[i].name.take(),
                    bytes: self.edit(bytes, &partner, words),
                };
            }
            files::join(&parts)
        } else {
            let mut bytes = input.to_vec();
            for _ in 0..1 + self.below(4) {
                bytes = self.edit(bytes, other, words);
            }
            bytes
        };
        out.truncate(MAX_INPUT);
        out
    }

    /// One edit of `bytes`.
    fn edit(&mut self, mut bytes: Vec<u8>, other: &[u8], words: &[&str]) -> Vec<u8> {
        let len = bytes.len();
        let at = self.below(len + 1);
        match self.below(12) {
            0 if len > 0 => {
                for _ in 0..1 + self.below(4) {
                    let i = self.below(len);
                    bytes[i] ^= 1 << self.below(8);
                }
            }
            1 if len > 0 => {
                let i = self.below(len);
                bytes[i] = self.rng.random();
            }
            2 => {
                let n = 1 + self.below(16);
                let new: Vec<u8> = if self.rng.random() {
                    (0..n).map(|_| self.rng.random()).collect()
                } else {
                    vec![self.rng.random(); n]
                };
                bytes.splice(at..at, new);
            }
            3 if len > 0 => {
                let n = 1 + self.below((len - at.min(len - 1)).min(64));
                let start = at.min(len - 1);
                bytes.drain(start..(start + n).min(len));
            }
            4 => {
                let value = INTERESTING[self.below(INTERESTING.len())];
                let value = if self.rng.random() {
                    value
                } else {
                    value.wrapping_neg()
                };
                let width = [1, 2, 4, 8][self.below(4)];
                let encoded = if self.rng.random() {
                    value.to_le_bytes()[..width].to_vec()
                } else {
                    value.to_be_bytes()[8 - width..].to_vec()
                };
                if self.rng.random() && at + width <= len {
                    bytes[at..at + width].copy_from_slice(&encoded);
                } else {
                    bytes.splice(at..at, encoded);
                }
            }
            5 | 6 => {
                let numbers = number_spans(&bytes);
                if numbers.is_empty() {
                    return self.edit(bytes, other, words);
                }
                let (start, end) = numbers[self.below(numbers.len())];
                let new = NUMBERS[self.below(NUMBERS.len())].as_bytes().to_vec();
                bytes.splice(start..end, new);
            }
            7 => bytes.truncate(at),
            8 if !other.is_empty() => {
                let start = self.below(other.len());
                let n = 1 + self.below((other.len() - start).min(4096));
                let chunk = other[start..start + n].to_vec();
                if self.rng.random() {
                    let end = (at + n).min(len);
                    bytes.splice(at..end, chunk);
                } else {
                    bytes.splice(at..at, chunk);
                }
            }
            9 if len > 0 => {
                let start = self.below(len);
                let n = 1 + self.below((len - start).min(1024));
                let chunk = bytes[start..start + n].to_vec();
                let times = 1 + self.below(64);
                let repeated: Vec<u8> = chunk.iter().copied().cycle().take(n * times).collect();
                bytes.splice(at..at, repeated);
            }
            10 | 11 if !words.is_empty() => {
                let word = words[self.below(words.len())].as_bytes();
                if self.rng.random() && at + word.len() <= len {
                    bytes[at..at + word.len()].copy_from_slice(word);
                } else {
                    bytes.splice(at..at, word.iter().copied());
                }
            }
            _ => {
                // The chosen edit needs bytes the input lacks: add one.
                bytes.insert(at, self.rng.random());
            }
        }
        bytes
    }
}

/// The spans of the decimal numbers of a text (`-` and digits, with `.`, exponents).
fn number_spans(bytes: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let starts = bytes[i].is_ascii_digit()
            || (bytes[i] == b'-' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit));
        if starts && (i == 0 || !bytes[i - 1].is_ascii_alphanumeric()) {
            let mut end = i + 1;
            while end < bytes.len()
                && (bytes[end].is_ascii_digit()
                    || matches!(bytes[end], b'.' | b'e' | b'E')
                    || (matches!(bytes[end], b'+' | b'-') && matches!(bytes[end - 1], b'e' | b'E')))
            {
                end += 1;
            }
            spans.push((i, end));
            i = end;
        } else {
            i += 1;
        }
    }
    spans
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_found() {
        let text = b"{\"a\": -1.5e3, \"b2\": [7, 0.25]}";
        let spans: Vec<&[u8]> = number_spans(text)
            .into_iter()
            .map(|(s, e)| &text[s..e])
            .collect();
        assert_eq!(spans, [&b"-1.5e3"[..], b"7", b"0.25"]);
    }

    #[test]
    fn mutants_are_deterministic_and_bounded() {
        let input = b"{\"count\": 3}\n--8<-- scene.bin\n\x01\x02\x03";
        let run = |seed| {
            let mut m = Mutator::new(seed);
            (0..200)
                .map(|_| m.mutate(input, b"other", true, &["\"uri\""]))
                .collect::<Vec<_>>()
        };
        let (a, b) = (run(7), run(7));
        assert_eq!(a, b);
        assert_ne!(a, run(8));
        assert!(a.iter().all(|m| m.len() <= MAX_INPUT));
        assert!(a.iter().any(|m| m.as_slice() != input));
    }
}
