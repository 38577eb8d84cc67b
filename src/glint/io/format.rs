//! The binary file format of built glint maps (and of normal maps): primitives shared by every model.
//!
//! A file is a 24-byte header, a payload, and an 8-byte checksum, all little-endian:
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 8 | magic `BRDFGLNT` |
//! | 8 | 4 | format version ([`VERSION`]) |
//! | 12 | 4 | model kind ([`Kind`]) |
//! | 16 | 8 | payload length P in bytes |
//! | 24 | P | payload: the model's parameters, then its arrays, each preceded by its element count |
//! | 24 + P | 8 | checksum ([`Checksum`]) of bytes [0, 24 + P) |
//!
//! The header is read and judged by [`read_header`](super::header::read_header) (foreign bytes, a
//! damaged header, an intact file of a version or kind not read).
//!
//! The full description, payload by payload, is docs/format.md. The reader trusts nothing: every
//! length is checked against the model's parameters and against what the declared payload can hold
//! before anything is allocated, and arrays are read in bounded chunks, so a file that claims more
//! than it holds fails with [`Error::Truncated`] having allocated at most about what it did hold.

use super::checksum::Checksum;
pub(crate) use super::header::Kind;
use super::header::{MAGIC, VERSION};
use super::header::{Seal, confirm, read_header};
use crate::{Error, Result};
use std::io::{Read, Write};

/// Arrays are converted and hashed through a buffer of this many bytes (and grown by at most this
/// much per read), so a lying length costs at most one chunk beyond the bytes actually present.
const CHUNK_BYTES: usize = 1 << 16;

/// A type kept in the crate's file format, implemented by each stored model in its own module: the
/// run-time [`GlintModel`](crate::glint::GlintModel) saves and loads through it.
pub(crate) trait Stored: Sized {
    /// The kinds the loader reads (a file of another kind is not this type's).
    const KINDS: &'static [Kind];
    /// Writes the whole file (the type's `save`).
    fn save_to(&self, w: &mut dyn Write) -> Result<()>;
    /// Reads a whole file (the type's `load`).
    fn load_from(r: &mut dyn Read) -> Result<Self>;
}

fn stream(source: std::io::Error) -> Error {
    Error::Stream { source }
}

/// A value that can be written to and read from a file as fixed-size little-endian bytes.
///
/// `Pod` lets arrays be read straight into their final storage (one copy from the reader, no
/// per-scalar decoding); [`Scalar::le_to_native`] then reorders the bytes on a big-endian target and is
/// the identity (compiled away) on a little-endian one.
pub(crate) trait Scalar: Copy + bytemuck::Pod {
    const BYTES: usize;
    fn put(self, out: &mut Vec<u8>);
    fn get(b: &[u8]) -> Self;
    /// The value whose little-endian bytes are this value's in-memory bytes.
    fn le_to_native(self) -> Self;
}

macro_rules! scalar {
    ($t:ty, $n:expr) => {
        impl Scalar for $t {
            const BYTES: usize = $n;
            #[inline]
            fn put(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_le_bytes());
            }
            #[inline]
            fn get(b: &[u8]) -> Self {
                let mut a = [0u8; $n];
                a.copy_from_slice(&b[..$n]);
                <$t>::from_le_bytes(a)
            }
            #[inline]
            fn le_to_native(self) -> Self {
                <$t>::from_le_bytes(self.to_ne_bytes())
            }
        }
    };
}
scalar!(u8, 1);
scalar!(u16, 2);
scalar!(u32, 4);
scalar!(u64, 8);
scalar!(f32, 4);
scalar!(f64, 8);

/// Writes one file: a counting pass (to put the payload length in the header) and a writing pass
/// run the same `payload` function.
pub(crate) struct Encoder<'a> {
    out: Option<&'a mut dyn Write>,
    sum: Checksum,
    buf: Vec<u8>,
    count: u64,
}

impl Encoder<'_> {
    fn flush_buf(&mut self) -> Result<()> {
        if let Some(w) = self.out.as_mut() {
            self.sum.update(&self.buf);
            w.write_all(&self.buf).map_err(stream)?;
        }
        self.buf.clear();
        Ok(())
    }

    /// One scalar.
    pub(crate) fn put<T: Scalar>(&mut self, v: T) -> Result<()> {
        self.count += T::BYTES as u64;
        if self.out.is_some() {
            v.put(&mut self.buf);
            if self.buf.len() >= CHUNK_BYTES {
                self.flush_buf()?;
            }
        }
        Ok(())
    }

    /// A `usize` as `u64`.
    pub(crate) fn len(&mut self, n: usize) -> Result<()> {
        self.put(n as u64)
    }

    /// An array of fixed-size records: its element count (u64), then the records' scalars in order.
    pub(crate) fn array<T: Scalar, const N: usize>(
        &mut self,
        items: impl ExactSizeIterator<Item = [T; N]>,
    ) -> Result<()> {
        self.len(items.len())?;
        self.count += (items.len() * N * T::BYTES) as u64;
        if self.out.is_none() {
            return Ok(());
        }
        for item in items {
            for v in item {
                v.put(&mut self.buf);
            }
            if self.buf.len() >= CHUNK_BYTES {
                self.flush_buf()?;
            }
        }
        Ok(())
    }
}

/// Writes a whole file of model `kind` whose payload `payload` writes (called twice: counting, then
/// writing; it must write the same fields both times).
pub(crate) fn save(
    w: &mut dyn Write,
    kind: Kind,
    payload: impl Fn(&mut Encoder<'_>) -> Result<()>,
) -> Result<()> {
    let mut counter = Encoder {
        out: None,
        sum: Checksum::new(),
        buf: Vec::new(),
        count: 0,
    };
    payload(&mut counter)?;
    let mut enc = Encoder {
        out: Some(w),
        sum: Checksum::new(),
        buf: Vec::with_capacity(CHUNK_BYTES + 64),
        count: 0,
    };
    enc.buf.extend_from_slice(&MAGIC);
    enc.buf.extend_from_slice(&VERSION.to_le_bytes());
    enc.buf.extend_from_slice(&(kind as u32).to_le_bytes());
    enc.buf.extend_from_slice(&counter.count.to_le_bytes());
    payload(&mut enc)?;
    debug_assert_eq!(enc.count, counter.count);
    enc.flush_buf()?;
    let sum = std::mem::replace(&mut enc.sum, Checksum::new()).finish();
    if let Some(w) = enc.out.as_mut() {
        w.write_all(&sum.to_le_bytes()).map_err(stream)?;
        w.flush().map_err(stream)?;
    }
    Ok(())
}

/// Reads one file: header checked on creation, fields in order, checksum checked by
/// [`Decoder::finish`].
pub(crate) struct Decoder<'a> {
    r: &'a mut dyn Read,
    sum: Checksum,
    /// Payload bytes not read yet (as declared by the header).
    remaining: u64,
    /// The first value found out of range by [`Decoder::array_in_range`], reported by
    /// [`Decoder::finish`] once the checksum has been checked.
    out_of_range: Option<Error>,
    /// The file's format version ([`OLDEST_READ`](super::header::OLDEST_READ) ..= [`VERSION`]).
    version: u32,
}

impl<'a> Decoder<'a> {
    /// Reads and checks the header ([`read_header`](super::header::read_header)): magic, version,
    /// kind.
    ///
    /// # Errors
    /// [`Error::Truncated`], [`Error::BadMagic`], [`Error::CorruptHeader`],
    /// [`Error::UnsupportedVersion`], [`Error::WrongModelKind`], [`Error::Stream`].
    pub(crate) fn open(r: &'a mut dyn Read, expected: Kind) -> Result<Decoder<'a>> {
        Self::open_any(r, &[expected]).map(|(d, _)| d)
    }

    /// [`Decoder::open`] for a loader that reads several kinds (`expected`, not empty): the
    /// decoder and the kind found ([`Error::WrongModelKind`] names the first expected kind).
    pub(crate) fn open_any(r: &'a mut dyn Read, expected: &[Kind]) -> Result<(Decoder<'a>, Kind)> {
        let header = read_header(r, expected, &Kind::name(expected[0] as u32))?;
        let mut sum = Checksum::new();
        sum.update(&header.bytes);
        Ok((
            Decoder {
                r,
                sum,
                remaining: header.payload,
                out_of_range: None,
                version: header.version,
            },
            header.kind,
        ))
    }

    /// Whether the rest of the file, as the header declares it, matches its checksum (reads it:
    /// only for judging an error).
    fn seal(&mut self) -> Result<Seal> {
        let sum = std::mem::replace(&mut self.sum, Checksum::new());
        let remaining = std::mem::take(&mut self.remaining);
        confirm(self.r, sum, remaining)
    }

    /// The file's format version.
    pub(crate) fn version(&self) -> u32 {
        self.version
    }

    /// Refuses a file older than `oldest` (a payload whose layout changed in that version), judged
    /// as the header's other fields are (an intact file is unsupported, a damaged one corrupted).
    ///
    /// # Errors
    /// [`Error::UnsupportedVersion`], [`Error::CorruptHeader`], [`Error::Truncated`],
    /// [`Error::Stream`].
    pub(crate) fn require_version(&mut self, oldest: u32) -> Result<()> {
        if self.version >= oldest {
            return Ok(());
        }
        let version = self.version;
        let intact = Error::UnsupportedVersion {
            found: version,
            supported: VERSION,
        };
        Err(self.seal()?.judge(intact, "version", || {
            format!(
                "this kind is read from version {oldest} on, the header says {version}, and the \
                 file's checksum does not match"
            )
        }))
    }

    /// Counts `n` more payload bytes against what the header declares. A field that needs more than
    /// is left is judged by the checksum: an intact file is inconsistent ([`Error::InvalidFile`]),
    /// a damaged one has a payload length (or a count read before) that is wrong
    /// ([`Error::CorruptHeader`]).
    fn take(&mut self, n: usize, what: &'static str) -> Result<()> {
        if (n as u64) <= self.remaining {
            self.remaining -= n as u64;
            return Ok(());
        }
        let left = self.remaining;
        let intact = Error::InvalidFile {
            reason: format!(
                "{what} needs {n} more bytes but the header declares only {left} left in the payload"
            ),
        };
        Err(self.seal()?.judge(intact, "payload length", || {
            format!(
                "{what} needs {n} more bytes but the header declares only {left} left in the \
                 payload, and the file's checksum does not match (the payload length, or a count \
                 read before {what}, is damaged)"
            )
        }))
    }

    /// One scalar.
    pub(crate) fn get<T: Scalar>(&mut self, what: &'static str) -> Result<T> {
        self.take(T::BYTES, what)?;
        let mut b = [0u8; 8];
        read_exact(self.r, &mut b[..T::BYTES], what)?;
        self.sum.update(&b[..T::BYTES]);
        Ok(T::get(&b))
    }

    /// A count stored as u64, which must fit a `usize` and not exceed `max`.
    pub(crate) fn len(&mut self, what: &'static str, max: usize) -> Result<usize> {
        let n: u64 = self.get(what)?;
        match usize::try_from(n) {
            Ok(n) if n <= max => Ok(n),
            _ => Err(Error::InvalidFile {
                reason: format!("{what} = {n} exceeds the limit {max}"),
            }),
        }
    }

    /// An array written by [`Encoder::array`] whose element count must equal `expected` (derived
    /// from the parameters already read). The count is checked against `expected` and against the
    /// declared payload before anything is allocated; records are read in chunks.
    pub(crate) fn array<T: Scalar, const N: usize>(
        &mut self,
        what: &'static str,
        expected: usize,
    ) -> Result<Vec<[T; N]>> {
        self.array_with(what, expected, |_, _| {})
    }

    /// [`Decoder::array`] that also shows every chunk of records to `chunk(index of its first
    /// record, records)` as it is read (while it is in cache).
    pub(crate) fn array_with<T: Scalar, const N: usize>(
        &mut self,
        what: &'static str,
        expected: usize,
        chunk: impl FnMut(usize, &[[T; N]]),
    ) -> Result<Vec<[T; N]>> {
        let n: u64 = self.get(what)?;
        if n != expected as u64 {
            return Err(Error::InvalidFile {
                reason: format!(
                    "{what} holds {n} elements but the parameters read so far need {expected}"
                ),
            });
        }
        self.records_with(what, expected, chunk)
    }

    /// An array written by [`Encoder::array`] whose element count is free up to `max` (checked, as
    /// everything else, before allocating).
    pub(crate) fn array_up_to<T: Scalar, const N: usize>(
        &mut self,
        what: &'static str,
        max: usize,
    ) -> Result<Vec<[T; N]>> {
        let n = self.len(what, max)?;
        self.records(what, n)
    }

    /// [`Decoder::array`] of `f32` records whose values must all be finite and within
    /// `bound(component)` = [lo, hi], checked chunk by chunk as the records are read (while they
    /// are in cache, instead of a second pass over the array). A value out of range is reported by
    /// [`Decoder::finish`] after the payload length and the checksum (so a damaged file still gets
    /// [`Error::ChecksumMismatch`]), as the [`Error::InvalidFile`] [`check_range`] gives.
    pub(crate) fn array_in_range<const N: usize>(
        &mut self,
        what: &'static str,
        expected: usize,
        bound: impl Fn(usize) -> (f32, f32),
    ) -> Result<Vec<[f32; N]>> {
        let bounds: [(f32, f32); N] = std::array::from_fn(&bound);
        let mut bad = None;
        let out = self.array_with(what, expected, |first, chunk: &[[f32; N]]| {
            if bad.is_none() && !all_in_range(chunk, &bounds) {
                bad = first_out_of_range(chunk, first, what, &bounds).err();
            }
        })?;
        if self.out_of_range.is_none() {
            self.out_of_range = bad;
        }
        Ok(out)
    }

    /// Reads `expected` records (see [`Decoder::records_with`]).
    fn records<T: Scalar, const N: usize>(
        &mut self,
        what: &'static str,
        expected: usize,
    ) -> Result<Vec<[T; N]>> {
        self.records_with(what, expected, |_, _| {})
    }

    /// Reads `expected` records: bytes go from the reader into a chunk of records (no per-scalar
    /// decoding), are hashed there, shown to `chunk(index of its first record, records)` and
    /// appended to the vector, which grows as data arrive (so a file that declares more than it
    /// holds allocates at most about twice what it did hold). The bytes are reordered in place
    /// (before `chunk` sees them) only on a big-endian target.
    fn records_with<T: Scalar, const N: usize>(
        &mut self,
        what: &'static str,
        expected: usize,
        mut chunk_seen: impl FnMut(usize, &[[T; N]]),
    ) -> Result<Vec<[T; N]>> {
        let record = N * T::BYTES;
        let bytes = expected
            .checked_mul(record)
            .ok_or_else(|| Error::InvalidFile {
                reason: format!("{what}: {expected} elements overflow the address space"),
            })?;
        self.take(bytes, what)?;
        let per_chunk = (CHUNK_BYTES / record).max(1);
        let mut out: Vec<[T; N]> = Vec::with_capacity(expected.min(per_chunk));
        let mut buf = vec![[T::zeroed(); N]; expected.min(per_chunk)];
        let mut left = expected;
        while left > 0 {
            let k = left.min(per_chunk);
            let chunk = &mut buf[..k];
            let raw: &mut [u8] = bytemuck::cast_slice_mut(chunk.as_flattened_mut());
            read_exact(self.r, raw, what)?;
            self.sum.update(raw);
            if cfg!(target_endian = "big") {
                for v in chunk.iter_mut().flatten() {
                    *v = v.le_to_native();
                }
            }
            chunk_seen(out.len(), chunk);
            out.extend_from_slice(chunk);
            left -= k;
        }
        Ok(out)
    }

    /// Checks that the payload was read exactly and that the checksum matches.
    ///
    /// # Errors
    /// Payload bytes left over: [`Error::InvalidFile`] if the file's checksum matches (a file
    /// written inconsistent), else [`Error::CorruptHeader`] (the fields were all read, so the
    /// declared length is what is wrong), also when the file ends before the declared length.
    /// [`Error::Truncated`] if the checksum is missing, [`Error::ChecksumMismatch`].
    /// Then reports the first value [`Decoder::array_in_range`] found out of range, if any.
    pub(crate) fn finish(mut self) -> Result<()> {
        if self.remaining != 0 {
            let extra = self.remaining;
            let intact = Error::InvalidFile {
                reason: format!(
                    "the header declares {extra} payload bytes more than the model's fields hold"
                ),
            };
            let seal = match self.seal()? {
                Seal::EndsEarly(_) => Seal::Broken,
                seal => seal,
            };
            return Err(seal.judge(intact, "payload length", || {
                format!(
                    "the header declares {extra} payload bytes more than the model's fields hold, \
                     and the file's checksum does not match or the file ends before it (the \
                     payload length, or the version that sets the fields, is damaged)"
                )
            }));
        }
        let mut b = [0u8; 8];
        read_exact(self.r, &mut b, "the checksum")?;
        let stored = u64::from_le_bytes(b);
        let computed = self.sum.finish();
        if stored != computed {
            return Err(Error::ChecksumMismatch { stored, computed });
        }
        match self.out_of_range {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}

fn read_exact(r: &mut dyn Read, buf: &mut [u8], what: &'static str) -> Result<()> {
    r.read_exact(buf).map_err(|e| {
        if e.kind() == std::io::ErrorKind::UnexpectedEof {
            Error::Truncated { what }
        } else {
            stream(e)
        }
    })
}

/// An [`Error::InvalidFile`] with a formatted reason.
pub(crate) fn invalid(reason: String) -> Error {
    Error::InvalidFile { reason }
}

/// Checks that every value is finite and within [lo, hi]; `what` names the array in the error.
///
/// The bounds are taken once per component and the items are scanned without an early exit (a
/// loop the compiler vectorises); only a failing array is scanned again to name its first bad value.
pub(crate) fn check_range<const N: usize>(
    items: &[[f32; N]],
    what: &str,
    bound: impl Fn(usize) -> (f32, f32),
) -> Result<()> {
    let bounds: [(f32, f32); N] = std::array::from_fn(&bound);
    if all_in_range(items, &bounds) {
        return Ok(());
    }
    first_out_of_range(items, 0, what, &bounds)
}

/// Whether every component c of every item is in [bounds[c].0, bounds[c].1] (NaN never is); no
/// early exit, so the loop vectorises.
#[inline]
fn all_in_range<const N: usize>(items: &[[f32; N]], bounds: &[(f32, f32); N]) -> bool {
    let inside = |item: &[f32; N]| {
        item.iter()
            .zip(bounds)
            .fold(true, |ok, (&v, &(lo, hi))| ok & (v >= lo) & (v <= hi))
    };
    items.iter().fold(true, |ok, item| ok & inside(item))
}

/// The [`Error::InvalidFile`] naming the first value out of range (items numbered from `first`).
#[cold]
fn first_out_of_range<const N: usize>(
    items: &[[f32; N]],
    first: usize,
    what: &str,
    bounds: &[(f32, f32); N],
) -> Result<()> {
    for (k, item) in items.iter().enumerate() {
        for (c, (&v, &(lo, hi))) in item.iter().zip(bounds).enumerate() {
            if !(v >= lo && v <= hi) {
                return Err(invalid(format!(
                    "{what}[{}][{c}] = {v} is outside [{lo}, {hi}] (or not finite)",
                    first + k
                )));
            }
        }
    }
    Ok(())
}
