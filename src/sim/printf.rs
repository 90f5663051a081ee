//! Device-side `printf`: what clang and nvcc make of a `printf` call in a
//! kernel, `vprintf(format, args)`, executed per lane.
//!
//! The CUDA ABI: `format` is a generic address of the NUL-terminated format
//! string, `args` a generic address of a buffer (in local memory) holding the
//! arguments after the default promotions (`float` → `double`, `char` and
//! `short` → `int`), each at the next multiple of its own size (4 bytes for
//! `int`, 8 for `long`, `long long`, `double` and pointers). [`format`]
//! formats one lane's call as the C library does; a `%s` argument is a
//! generic address of a string, read through the same [`Memory`].
//!
//! Output order is deterministic: each call adds one [`PrintfRecord`] per
//! active lane to the launch's [`PrintfSink`], and [`PrintfSink::take`]
//! returns them by launch, CTA (linear index), warp, the warp's calls in
//! program order, then lane: the same text for any host thread count. (A GPU
//! prints in whatever order its warps reach the call.)

use std::sync::Mutex;
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};

/// The function name clang and nvcc call for `printf`.
pub const VPRINTF: &str = "vprintf";

/// Longest string `%s` or a format reads before it stops (no NUL found).
pub const MAX_STRING: usize = 4096;

/// Most arguments one call formats (CUDA's limit).
pub const MAX_ARGS: usize = 32;

/// Byte-wise access to the memory a lane sees (generic addresses).
pub trait Memory {
    /// The byte at generic address `addr`, or `None` when it is not mapped.
    fn byte(&mut self, addr: u64) -> Option<u8>;
}

/// Why a `printf` call could not be formatted.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PrintfError {
    /// The format string or a `%s` string is not readable.
    #[error("printf: {what} at {addr:#x} is not readable memory")]
    Unreadable {
        /// What was read (`format string`, `argument 2`, `%s string`).
        what: String,
        /// The address.
        addr: u64,
    },
}

/// One lane's output of one call.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PrintfRecord {
    /// Launch number within the sink.
    pub launch: u32,
    /// CTA linear index.
    pub cta_linear: u32,
    /// CTA index (x, y, z).
    pub cta: [u32; 3],
    /// Warp within its CTA.
    pub warp: u32,
    /// Order of the call among all calls (increasing along each warp).
    pub seq: u64,
    /// Lane.
    pub lane: u32,
    /// The formatted text (usually ending in a newline).
    pub text: String,
}

/// The `printf` output of the launches on one device.
#[derive(Debug, Default)]
pub struct PrintfSink {
    records: Mutex<Vec<PrintfRecord>>,
    seq: AtomicU64,
    launches: AtomicU32,
}

impl PrintfSink {
    /// A number for a new launch (orders output between launches).
    pub fn begin_launch(&self) -> u32 {
        self.launches.fetch_add(1, Ordering::Relaxed)
    }

    /// A number for a new call; calls of one warp get increasing numbers.
    pub fn next_seq(&self) -> u64 {
        self.seq.fetch_add(1, Ordering::Relaxed)
    }

    /// Adds the records of one call.
    pub fn push(&self, recs: Vec<PrintfRecord>) {
        if !recs.is_empty() {
            self.records.lock().unwrap_or_else(|e| e.into_inner()).extend(recs);
        }
    }

    /// The output so far, in the deterministic order (launch, CTA, warp,
    /// call, lane), removing it from the sink.
    pub fn take(&self) -> Vec<PrintfRecord> {
        let mut v = std::mem::take(&mut *self.records.lock().unwrap_or_else(|e| e.into_inner()));
        v.sort_by_key(|r| (r.launch, r.cta_linear, r.warp, r.seq, r.lane));
        v
    }
}

/// Where a launch's `printf` calls go: the device's sink and the launch's number.
#[derive(Debug, Clone, Copy)]
pub struct PrintfTarget<'a> {
    /// The device's sink.
    pub sink: &'a PrintfSink,
    /// The launch ([`PrintfSink::begin_launch`]).
    pub launch: u32,
}

/// The records' text, concatenated.
pub fn text(recs: &[PrintfRecord]) -> String {
    recs.iter().map(|r| r.text.as_str()).collect()
}

/// Reads a NUL-terminated string (at most [`MAX_STRING`] bytes).
fn c_string(mem: &mut dyn Memory, addr: u64, what: &str) -> Result<Vec<u8>, PrintfError> {
    let mut s = Vec::new();
    for i in 0..MAX_STRING as u64 {
        let a = addr.wrapping_add(i);
        match mem.byte(a) {
            Some(0) => return Ok(s),
            Some(b) => s.push(b),
            None => return Err(PrintfError::Unreadable { what: what.into(), addr: a }),
        }
    }
    Ok(s)
}

/// The argument buffer: values at naturally aligned offsets.
struct Args<'m> {
    mem: &'m mut dyn Memory,
    base: u64,
    off: u64,
    count: usize,
}

impl Args<'_> {
    fn next(&mut self, size: u64) -> Result<u64, PrintfError> {
        self.off = self.off.div_ceil(size) * size;
        let mut v = 0u64;
        for i in 0..size {
            let a = self.base.wrapping_add(self.off + i);
            let b = self
                .mem
                .byte(a)
                .ok_or(PrintfError::Unreadable { what: format!("argument {}", self.count + 1), addr: a })?;
            v |= (b as u64) << (8 * i);
        }
        self.off += size;
        self.count += 1;
        Ok(v)
    }
}

/// One conversion's flags, width and precision.
#[derive(Debug, Default, Clone, Copy)]
struct Spec {
    left: bool,
    plus: bool,
    space: bool,
    alt: bool,
    zero: bool,
    width: usize,
    precision: Option<usize>,
}

impl Spec {
    /// Pads `body` (after `sign`/`prefix`) to the width.
    fn pad(&self, sign: &str, prefix: &str, body: &str, zero_ok: bool) -> String {
        let len = sign.len() + prefix.len() + body.chars().count();
        if len >= self.width {
            return format!("{sign}{prefix}{body}");
        }
        let fill = self.width - len;
        if self.left {
            format!("{sign}{prefix}{body}{}", " ".repeat(fill))
        } else if self.zero && zero_ok {
            format!("{sign}{prefix}{}{body}", "0".repeat(fill))
        } else {
            format!("{}{sign}{prefix}{body}", " ".repeat(fill))
        }
    }

    fn sign(&self, negative: bool) -> &'static str {
        if negative {
            "-"
        } else if self.plus {
            "+"
        } else if self.space {
            " "
        } else {
            ""
        }
    }
}

/// Formats one lane's `vprintf(format, args)`: the text and the number of
/// arguments used.
pub fn format(mem: &mut dyn Memory, fmt_addr: u64, args_addr: u64) -> Result<(String, usize), PrintfError> {
    let fmt = c_string(mem, fmt_addr, "format string")?;
    let mut args = Args { mem, base: args_addr, off: 0, count: 0 };
    let mut out: Vec<u8> = Vec::new();
    let mut i = 0;
    while i < fmt.len() {
        if fmt[i] != b'%' {
            out.push(fmt[i]);
            i += 1;
            continue;
        }
        let start = i;
        i += 1;
        let mut s = Spec::default();
        while let Some(&c) = fmt.get(i) {
            match c {
                b'-' => s.left = true,
                b'+' => s.plus = true,
                b' ' => s.space = true,
                b'#' => s.alt = true,
                b'0' => s.zero = true,
                _ => break,
            }
            i += 1;
        }
        if fmt.get(i) == Some(&b'*') {
            let w = args.next(4)? as u32 as i32;
            s.left |= w < 0;
            s.width = w.unsigned_abs() as usize;
            i += 1;
        } else {
            while let Some(d) = fmt.get(i).filter(|c| c.is_ascii_digit()) {
                s.width = s.width.saturating_mul(10).saturating_add((d - b'0') as usize);
                i += 1;
            }
        }
        if fmt.get(i) == Some(&b'.') {
            i += 1;
            if fmt.get(i) == Some(&b'*') {
                let p = args.next(4)? as u32 as i32;
                s.precision = (p >= 0).then_some(p as usize);
                i += 1;
            } else {
                let mut p = 0usize;
                while let Some(d) = fmt.get(i).filter(|c| c.is_ascii_digit()) {
                    p = p.saturating_mul(10).saturating_add((d - b'0') as usize);
                    i += 1;
                }
                s.precision = Some(p);
            }
        }
        // length: h and hh narrow a promoted int; l, ll, j, z, t take 8 bytes
        let mut len = "";
        for l in ["hh", "ll", "h", "l", "j", "z", "t", "L"] {
            if fmt[i..].starts_with(l.as_bytes()) {
                len = l;
                i += l.len();
                break;
            }
        }
        let Some(&conv) = fmt.get(i) else {
            out.extend_from_slice(&fmt[start..]);
            break;
        };
        i += 1;
        if args.count >= MAX_ARGS && conv != b'%' {
            out.extend_from_slice(&fmt[start..i]);
            continue;
        }
        let wide = matches!(len, "l" | "ll" | "j" | "z" | "t");
        let piece = match conv {
            b'%' => "%".to_string(),
            b'd' | b'i' => {
                let raw = args.next(if wide { 8 } else { 4 })?;
                let v: i64 = match len {
                    "hh" => raw as u8 as i8 as i64,
                    "h" => raw as u16 as i16 as i64,
                    _ if wide => raw as i64,
                    _ => raw as u32 as i32 as i64,
                };
                integer(&s, v < 0, &v.unsigned_abs().to_string(), "", true)
            }
            b'u' | b'x' | b'X' | b'o' => {
                let raw = args.next(if wide { 8 } else { 4 })?;
                let v: u64 = match len {
                    "hh" => raw as u8 as u64,
                    "h" => raw as u16 as u64,
                    _ if wide => raw,
                    _ => raw as u32 as u64,
                };
                let (digits, prefix) = match conv {
                    b'u' => (v.to_string(), ""),
                    b'x' => (format!("{v:x}"), if s.alt && v != 0 { "0x" } else { "" }),
                    b'X' => (format!("{v:X}"), if s.alt && v != 0 { "0X" } else { "" }),
                    _ => (format!("{v:o}"), if s.alt && v != 0 { "0" } else { "" }),
                };
                let mut s2 = s;
                s2.plus = false;
                s2.space = false;
                integer(&s2, false, &digits, prefix, true)
            }
            b'c' => {
                let c = args.next(4)? as u8;
                s.pad("", "", &String::from_utf8_lossy(&[c]), false)
            }
            b's' => {
                let p = args.next(8)?;
                let mut bytes = if p == 0 {
                    b"(null)".to_vec()
                } else {
                    c_string(args.mem, p, &format!("%s string (argument {})", args.count))?
                };
                if let Some(pr) = s.precision {
                    bytes.truncate(pr);
                }
                s.pad("", "", &String::from_utf8_lossy(&bytes), false)
            }
            b'p' => {
                let p = args.next(8)?;
                s.pad("", "0x", &format!("{p:x}"), false)
            }
            b'f' | b'F' | b'e' | b'E' | b'g' | b'G' => {
                let v = f64::from_bits(args.next(8)?);
                float(&s, conv, v)
            }
            // %a, %n and unknown conversions: copied as written (%a still takes its argument)
            b'a' | b'A' => {
                args.next(8)?;
                String::from_utf8_lossy(&fmt[start..i]).into_owned()
            }
            _ => String::from_utf8_lossy(&fmt[start..i]).into_owned(),
        };
        out.extend_from_slice(piece.as_bytes());
    }
    Ok((String::from_utf8_lossy(&out).into_owned(), args.count))
}

/// An integer conversion: `digits` with the precision's leading zeros.
fn integer(s: &Spec, negative: bool, digits: &str, prefix: &str, _signed: bool) -> String {
    let body = match s.precision {
        Some(0) if digits == "0" => String::new(),
        Some(p) if p > digits.len() => format!("{}{digits}", "0".repeat(p - digits.len())),
        _ => digits.to_string(),
    };
    s.pad(s.sign(negative), prefix, &body, s.precision.is_none())
}

/// `%e`'s text of `a` (finite, non-negative) with `p` digits after the point.
fn exp_form(a: f64, p: usize, upper: bool) -> String {
    let r = format!("{a:.p$e}");
    let (mant, exp) = r.split_once('e').expect("exponent");
    let e: i32 = exp.parse().expect("exponent digits");
    let sign = if e < 0 { '-' } else { '+' };
    let s = format!("{mant}e{sign}{:02}", e.unsigned_abs());
    if upper { s.to_uppercase() } else { s }
}

/// A floating-point conversion, as glibc prints it.
fn float(s: &Spec, conv: u8, v: f64) -> String {
    let upper = conv.is_ascii_uppercase();
    let negative = v.is_sign_negative();
    let a = v.abs();
    if !v.is_finite() {
        let t = if v.is_nan() { "nan" } else { "inf" };
        let t = if upper { t.to_uppercase() } else { t.to_string() };
        return s.pad(s.sign(negative), "", &t, false);
    }
    let p = s.precision.unwrap_or(6);
    let mut body = match conv {
        b'f' | b'F' => format!("{a:.p$}"),
        b'e' | b'E' => exp_form(a, p, upper),
        _ => {
            // %g: %e's exponent X decides; P significant digits
            let p = p.max(1);
            let x: i32 = exp_form(a, p - 1, false).split_once('e').expect("exponent").1.parse().expect("digits");
            let mut t = if (p as i32) > x && x >= -4 {
                let q = (p as i32 - 1 - x) as usize;
                format!("{a:.q$}")
            } else {
                exp_form(a, p - 1, upper)
            };
            if !s.alt {
                let (mant, exp) = match t.find(['e', 'E']) {
                    Some(k) => (t[..k].to_string(), t[k..].to_string()),
                    None => (t.clone(), String::new()),
                };
                let mant = if mant.contains('.') {
                    mant.trim_end_matches('0').trim_end_matches('.').to_string()
                } else {
                    mant
                };
                t = mant + &exp;
            }
            t
        }
    };
    if s.alt && !body.contains('.') {
        // '#': the point stays even without digits after it
        match body.find(['e', 'E']) {
            Some(k) => body.insert(k, '.'),
            None => body.push('.'),
        }
    }
    s.pad(s.sign(negative), "", &body, true)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat memory: the format at 0x1000, strings at 0x2000, arguments at 0x3000.
    struct Flat(Vec<(u64, Vec<u8>)>);
    impl Memory for Flat {
        fn byte(&mut self, addr: u64) -> Option<u8> {
            self.0.iter().find_map(|(b, v)| addr.checked_sub(*b).and_then(|o| v.get(o as usize).copied()))
        }
    }

    enum A {
        I(i32),
        L(i64),
        D(f64),
        P(u64),
    }

    fn run(fmt: &str, args: &[A]) -> String {
        let mut buf = Vec::new();
        for a in args {
            let (bytes, size): (Vec<u8>, usize) = match a {
                A::I(v) => (v.to_le_bytes().to_vec(), 4),
                A::L(v) => (v.to_le_bytes().to_vec(), 8),
                A::D(v) => (v.to_le_bytes().to_vec(), 8),
                A::P(v) => (v.to_le_bytes().to_vec(), 8),
            };
            buf.resize(buf.len().div_ceil(size) * size, 0xAA);
            buf.extend(bytes);
        }
        let mut f = fmt.as_bytes().to_vec();
        f.push(0);
        let mut mem = Flat(vec![(0x1000, f), (0x2000, b"hello\0".to_vec()), (0x3000, buf)]);
        format(&mut mem, 0x1000, 0x3000).unwrap().0
    }

    #[test]
    fn integers_as_the_c_library_prints_them() {
        use A::*;
        assert_eq!(
            run("%d|%5d|%-5d|%05d|%+d|% d", &[I(-42), I(42), I(42), I(-42), I(7), I(7)]),
            "-42|   42|42   |-0042|+7| 7"
        );
        assert_eq!(
            run("%u %x %X %#x %o %#o", &[I(-1), I(255), I(255), I(255), I(8), I(8)]),
            "4294967295 ff FF 0xff 10 010"
        );
        assert_eq!(run("%.3d|%8.3d|%.0d|%hhd|%hd", &[I(7), I(-7), I(0), I(300), I(70000)]), "007|    -007||44|4464");
        assert_eq!(
            run("%ld %lld %llu %lx", &[L(-5_000_000_000), L(i64::MIN), L(-1), L(1 << 40)]),
            "-5000000000 -9223372036854775808 18446744073709551615 10000000000"
        );
        // int, then a long at the next multiple of 8
        assert_eq!(run("%d %lld %d", &[I(1), L(2), I(3)]), "1 2 3");
        assert_eq!(run("%*d|%-*d|%.*d", &[I(4), I(1), I(3), I(2), I(3), I(5)]), "   1|2  |005");
    }

    #[test]
    fn floats_as_the_c_library_prints_them() {
        use A::*;
        assert_eq!(
            run("%f %.2f %8.3f %-8.1f|%+.0f %#.0f", &[D(1.5), D(3.14659), D(-2.5), D(0.25), D(2.5), D(3.0)]),
            "1.500000 3.15   -2.500 0.2     |+2 3."
        );
        assert_eq!(
            run("%e %.2E %e %e", &[D(12345.678), D(-0.000123), D(0.0), D(1e300)]),
            "1.234568e+04 -1.23E-04 0.000000e+00 1.000000e+300"
        );
        assert_eq!(
            run("%g %g %g %g %g %G", &[D(100000.0), D(1e6), D(0.0001), D(0.00001), D(1.5), D(1e-10)]),
            "100000 1e+06 0.0001 1e-05 1.5 1E-10"
        );
        assert_eq!(run("%.3g %#g %g %010.2f", &[D(1.23456), D(1.0), D(0.0), D(-1.23456)]), "1.23 1.00000 0 -000001.23");
        assert_eq!(
            run("%f %f %F %5.1f", &[D(f64::INFINITY), D(f64::NEG_INFINITY), D(f64::NAN), D(f64::NAN)]),
            "inf -inf NAN   nan"
        );
    }

    #[test]
    fn strings_characters_and_pointers() {
        use A::*;
        assert_eq!(
            run("[%s] [%8s] [%-8s] [%.3s] [%s]", &[P(0x2000), P(0x2000), P(0x2000), P(0x2000), P(0)]),
            "[hello] [   hello] [hello   ] [hel] [(null)]"
        );
        assert_eq!(
            run("%c%c%3c %p %% %a", &[I(b'o' as i32), I(b'k' as i32), I(b'!' as i32), P(0x2000), D(1.0)]),
            "ok  ! 0x2000 % %a"
        );
    }

    #[test]
    fn unreadable_memory_is_an_error_not_a_panic() {
        let mut mem = Flat(vec![(0x1000, b"%s\0".to_vec()), (0x3000, 0x9999u64.to_le_bytes().to_vec())]);
        let e = format(&mut mem, 0x1000, 0x3000).unwrap_err();
        assert_eq!(e, PrintfError::Unreadable { what: "%s string (argument 1)".into(), addr: 0x9999 });
        assert!(format(&mut mem, 0x5000, 0x3000).is_err());
        // a format without NUL in MAX_STRING bytes ends there
        let mut long = Flat(vec![(0x1000, vec![b'x'; MAX_STRING + 10])]);
        assert_eq!(format(&mut long, 0x1000, 0).unwrap().0.len(), MAX_STRING);
    }

    #[test]
    fn the_sink_orders_by_launch_cta_warp_call_and_lane() {
        let sink = PrintfSink::default();
        let rec = |launch, cta_linear, warp, seq, lane| PrintfRecord {
            launch,
            cta_linear,
            cta: [cta_linear, 0, 0],
            warp,
            seq,
            lane,
            text: format!("{launch}{cta_linear}{warp}{seq}{lane} "),
        };
        sink.push(vec![rec(0, 1, 0, 5, 0), rec(0, 1, 0, 5, 1)]);
        sink.push(vec![rec(0, 0, 1, 6, 3)]);
        sink.push(vec![rec(0, 0, 0, 7, 2), rec(1, 0, 0, 0, 0)]);
        assert_eq!(text(&sink.take()), "00072 00163 01050 01051 10000 ");
        assert!(sink.take().is_empty());
    }
}
