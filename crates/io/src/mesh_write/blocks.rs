//! The byte pipeline of every writer: `Sink` hands chunks of about a megabyte to the destination
//! on one thread while they are filled on another; `Text` encodes blocks of records in parallel and
//! appends them in order.

use crate::{Error, Result};
use rayon::prelude::*;
use std::io::Write;

pub(super) const CHUNK: usize = 1 << 20;

/// Full buffers that may wait for the writing thread: enough for the encoders to run a batch of
/// blocks ahead of it.
const QUEUED: usize = 6;

/// Bytes being assembled, with the number formatting of the text formats.
pub(super) struct Text {
    pub(super) buf: Vec<u8>,
    float: ryu::Buffer,
}

impl Text {
    pub(super) fn new(buf: Vec<u8>) -> Text {
        Text {
            buf,
            float: ryu::Buffer::new(),
        }
    }

    #[inline]
    pub(super) fn bytes(&mut self, b: &[u8]) {
        self.buf.extend_from_slice(b);
    }

    /// Shortest decimal text that parses back to the same `f32` (the value is finite: checked).
    #[inline]
    pub(super) fn f32_text(&mut self, x: f32) {
        let s = self.float.format_finite(x);
        self.buf.extend_from_slice(s.as_bytes());
    }

    /// Shortest decimal text that parses back to the same `f64` (the value is finite: checked).
    #[inline]
    pub(super) fn f64_text(&mut self, x: f64) {
        let s = self.float.format_finite(x);
        self.buf.extend_from_slice(s.as_bytes());
    }

    #[inline]
    pub(super) fn uint_text(&mut self, mut x: u64) {
        let mut tmp = [0u8; 20];
        let mut k = tmp.len();
        loop {
            k -= 1;
            tmp[k] = b'0' + (x % 10) as u8;
            x /= 10;
            if x == 0 {
                break;
            }
        }
        self.buf.extend_from_slice(&tmp[k..]);
    }

    #[inline]
    pub(super) fn u32_le(&mut self, x: u32) {
        self.buf.extend_from_slice(&x.to_le_bytes());
    }

    /// One record of `N` bytes for each `k` of `range`, `record(k)`, straight into the buffer.
    #[inline(always)]
    pub(super) fn records<const N: usize>(
        &mut self,
        range: std::ops::Range<usize>,
        record: impl Fn(usize) -> [u8; N],
    ) {
        let n = range.len();
        let start = self.buf.len();
        self.buf.reserve(n * N);
        let dst = self.buf.spare_capacity_mut()[..n * N]
            .as_mut_ptr()
            .cast::<u8>();
        for (r, k) in range.enumerate() {
            let bytes = record(k);
            // SAFETY: `dst` points to `n·N` reserved bytes; record `r` fills its own `N`.
            unsafe { std::ptr::copy_nonoverlapping(bytes.as_ptr(), dst.add(r * N), N) };
        }
        // SAFETY: the loop wrote all `n·N` bytes after `start`.
        unsafe { self.buf.set_len(start + n * N) };
    }
}

/// A byte buffer that is passed on to the destination whenever it holds about [`CHUNK`]
/// bytes, and blocks of records encoded on the thread pool ([`Sink::blocks`]).
pub(super) struct Sink {
    text: Text,
    /// To the thread that writes the full buffers ([`stream`]).
    full: std::sync::mpsc::SyncSender<Vec<u8>>,
    /// The emptied buffers it hands back.
    empty: std::sync::mpsc::Receiver<Vec<u8>>,
    what: &'static str,
}

impl std::ops::Deref for Sink {
    type Target = Text;
    fn deref(&self) -> &Text {
        &self.text
    }
}

impl std::ops::DerefMut for Sink {
    fn deref_mut(&mut self) -> &mut Text {
        &mut self.text
    }
}

/// Runs `body` on a second thread while this one writes the chunks it fills to `w`, in order:
/// encoding the next megabytes (on the thread pool, for [`Sink::blocks`]) overlaps handing the
/// last ones to the operating system (for a file, copying them into the page cache). Emptied
/// buffers come back to be filled again. A write error stops the encoding and is the error
/// reported; then `w` is flushed.
pub(super) fn stream<F>(w: &mut dyn Write, what: &'static str, body: F) -> Result<()>
where
    F: FnOnce(&mut Sink) -> Result<()> + Send,
{
    use std::sync::mpsc::{channel, sync_channel};
    let (full_tx, full_rx) = sync_channel::<Vec<u8>>(QUEUED);
    let (empty_tx, empty_rx) = channel::<Vec<u8>>();
    let io = |e: std::io::Error| Error::io_from(format!("writing {what}: {e}"), e);
    std::thread::scope(|scope| {
        let producer = scope.spawn(move || {
            let mut sink = Sink {
                text: Text::new(Vec::with_capacity(CHUNK + 4096)),
                full: full_tx,
                empty: empty_rx,
                what,
            };
            body(&mut sink)?;
            sink.drain()
        });
        let mut written = Ok(());
        for chunk in full_rx.iter() {
            if let Err(e) = w.write_all(&chunk) {
                written = Err(io(e));
                break;
            }
            // The producer may have finished: then the buffer is not needed.
            let _ = empty_tx.send(chunk);
        }
        // Unblocks a producer still sending after a write error.
        drop(full_rx);
        drop(empty_tx);
        let produced = match producer.join() {
            Ok(r) => r,
            Err(panic) => std::panic::resume_unwind(panic),
        };
        written?;
        produced?;
        w.flush().map_err(io)
    })
}

impl Sink {
    /// Passes the buffer on once it is full; call between records.
    #[inline]
    fn tick(&mut self) -> Result<()> {
        if self.text.buf.len() >= CHUNK {
            self.drain()?;
        }
        Ok(())
    }

    /// An emptied buffer handed back by the writing thread, or a new one.
    fn spare(&mut self) -> Vec<u8> {
        let mut buf = self
            .empty
            .try_recv()
            .unwrap_or_else(|_| Vec::with_capacity(CHUNK + 4096));
        buf.clear();
        buf
    }

    /// Hands a buffer to the writing thread.
    fn send(&mut self, buf: Vec<u8>) -> Result<()> {
        let what = self.what;
        // A closed channel means the writing side stopped on an error, which it reports.
        self.full
            .send(buf)
            .map_err(|_| Error::io(format!("writing {what}: stopped")))
    }

    /// Passes the buffer on (when it holds anything).
    fn drain(&mut self) -> Result<()> {
        if self.text.buf.is_empty() {
            return Ok(());
        }
        let next = self.spare();
        let buf = std::mem::replace(&mut self.text.buf, next);
        self.send(buf)
    }

    /// Encodes the items `0..count` in blocks of `per` (about a chunk of bytes each), several
    /// blocks at once on the thread pool, each by `encode(block, text)` into a buffer of its
    /// own, and passes the blocks on in order after what the buffer already holds.
    pub(super) fn blocks(
        &mut self,
        count: usize,
        per: usize,
        encode: impl Fn(std::ops::Range<usize>, &mut Text) + Sync,
    ) -> Result<()> {
        let per = per.max(1);
        let blocks = count.div_ceil(per);
        if blocks <= 1 {
            encode(0..count, &mut self.text);
            return self.tick();
        }
        self.drain()?;
        let batch = 2 * rayon::current_num_threads().max(1);
        let mut first = 0;
        while first < blocks {
            let end = (first + batch).min(blocks);
            let mut texts: Vec<Text> = (first..end).map(|_| Text::new(self.spare())).collect();
            texts.par_iter_mut().enumerate().for_each(|(b, text)| {
                let start = (first + b) * per;
                encode(start..(start + per).min(count), text);
            });
            for text in texts {
                self.send(text.buf)?;
            }
            first = end;
        }
        Ok(())
    }

    /// One record of `N` bytes for each of `0..count`, `record(k)` ([`Sink::blocks`]).
    pub(super) fn records<const N: usize>(
        &mut self,
        count: usize,
        record: impl Fn(usize) -> [u8; N] + Sync,
    ) -> Result<()> {
        self.blocks(count, CHUNK / 2 / N, |range, text| {
            text.records(range, &record)
        })
    }
}

/// Three 32-bit words, little-endian.
#[inline(always)]
pub(super) fn le3(v: [u32; 3]) -> [u8; 12] {
    let mut b = [0u8; 12];
    for (dst, x) in b.chunks_exact_mut(4).zip(v) {
        dst.copy_from_slice(&x.to_le_bytes());
    }
    b
}

/// Two arrays of bytes as one.
#[inline(always)]
pub(super) fn join_bytes<const A: usize, const B: usize, const N: usize>(
    a: [u8; A],
    b: [u8; B],
) -> [u8; N] {
    let mut out = [0u8; N];
    out[..A].copy_from_slice(&a);
    out[A..].copy_from_slice(&b);
    out
}

/// Lines of text per block encoded at once ([`Sink::blocks`]): well under a chunk.
pub(super) const LINES: usize = 1 << 13;
