//! The machine's floors for the fresh-process mesh path: first-touch cost of fresh memory per
//! MiB (4 KiB pages, and 2 MiB pages where transparent huge pages are advised), write and copy
//! bandwidth of touched memory, and writing a file through the page cache; each with one and
//! two threads, median of 7 runs.
//!
//! `cargo bench -p pdeshape --bench memory_floors -- [MiB] [dir]` (default 256 MiB and
//! the system's temporary directory for the file).

use std::io::Write;
use std::time::Instant;

fn median(mut xs: Vec<f64>) -> f64 {
    xs.sort_by(|a, b| a.partial_cmp(b).unwrap());
    xs[xs.len() / 2]
}

/// Splits `buf` into `threads` parts and runs `f` on each at once.
fn parallel(buf: &mut [u8], threads: usize, f: impl Fn(&mut [u8]) + Sync) {
    let part = buf.len().div_ceil(threads);
    std::thread::scope(|s| {
        for chunk in buf.chunks_mut(part) {
            let f = &f;
            s.spawn(move || f(chunk));
        }
    });
}

/// A fresh, untouched buffer of `bytes` (its pages not yet mapped), optionally advised for huge
/// pages.
fn fresh(bytes: usize, huge: bool) -> Vec<u8> {
    let mut v: Vec<u8> = Vec::with_capacity(bytes);
    #[cfg(target_os = "linux")]
    if huge {
        let start = v.as_mut_ptr() as usize;
        let first = start.next_multiple_of(2 << 20);
        let last = (start + bytes) / (2 << 20) * (2 << 20);
        if last > first {
            // SAFETY: the range lies inside the allocation; the advice changes no contents.
            unsafe {
                libc::madvise(
                    first as *mut libc::c_void,
                    last - first,
                    libc::MADV_HUGEPAGE,
                );
            }
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = huge;
    // SAFETY: u8 has no invalid values; every byte is written before it is read below.
    unsafe { v.set_len(bytes) };
    v
}

fn main() {
    let args: Vec<String> = std::env::args().filter(|a| a != "--bench").collect();
    let mib: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(256);
    let dir = args
        .get(2)
        .map(std::path::PathBuf::from)
        .unwrap_or_else(std::env::temp_dir);
    let bytes = mib << 20;
    let runs = 7;
    println!("buffer {mib} MiB, median of {runs} runs");
    for threads in [1, 2] {
        for huge in [false, true] {
            let t: Vec<f64> = (0..runs)
                .map(|_| {
                    let mut v = fresh(bytes, huge);
                    let t = Instant::now();
                    // One store per 4 KiB page: the cost is the fault (and the kernel's zeroing).
                    parallel(&mut v, threads, |c| {
                        for k in (0..c.len()).step_by(4096) {
                            c[k] = 1;
                        }
                    });
                    let s = t.elapsed().as_secs_f64();
                    std::hint::black_box(&v);
                    s
                })
                .collect();
            let s = median(t);
            println!(
                "first touch, {threads} thread(s), {}: {:.3} ms/MiB ({:.2} GB/s)",
                if huge {
                    "huge pages advised"
                } else {
                    "4 KiB pages"
                },
                s * 1e3 / mib as f64,
                bytes as f64 / s / 1e9
            );
        }
        let mut a = fresh(bytes, false);
        parallel(&mut a, threads, |c| c.fill(1));
        let t: Vec<f64> = (0..runs)
            .map(|r| {
                let t = Instant::now();
                parallel(&mut a, threads, |c| c.fill(r as u8));
                t.elapsed().as_secs_f64()
            })
            .collect();
        let s = median(t);
        println!(
            "write touched memory, {threads} thread(s): {:.2} GB/s",
            bytes as f64 / s / 1e9
        );
        let mut b = fresh(bytes, false);
        parallel(&mut b, threads, |c| c.fill(2));
        let t: Vec<f64> = (0..runs)
            .map(|_| {
                let t = Instant::now();
                let part = bytes.div_ceil(threads);
                std::thread::scope(|s| {
                    for (d, src) in b.chunks_mut(part).zip(a.chunks(part)) {
                        s.spawn(move || d.copy_from_slice(src));
                    }
                });
                t.elapsed().as_secs_f64()
            })
            .collect();
        let s = median(t);
        println!(
            "copy touched memory, {threads} thread(s): {:.2} GB/s (of data copied)",
            bytes as f64 / s / 1e9
        );
    }
    // A file written in 1 MiB chunks and closed, as the mesh writers do; then also synced.
    let data = vec![7u8; bytes];
    for sync in [false, true] {
        let t: Vec<f64> = (0..runs)
            .map(|_| {
                let path = dir.join(format!("memory_floors_{}.bin", std::process::id()));
                let t = Instant::now();
                let mut f = std::fs::File::create(&path).unwrap();
                for c in data.chunks(1 << 20) {
                    f.write_all(c).unwrap();
                }
                if sync {
                    f.sync_all().unwrap();
                }
                drop(f);
                let s = t.elapsed().as_secs_f64();
                std::fs::remove_file(&path).unwrap();
                s
            })
            .collect();
        let s = median(t);
        println!(
            "file write through the page cache{}: {:.2} GB/s",
            if sync { " and fsync" } else { ", to close" },
            bytes as f64 / s / 1e9
        );
    }
}
