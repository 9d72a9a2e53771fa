use super::*;

fn fails<T>(r: Result<T, OpenError>) -> OpenError {
    match r {
        Ok(_) => panic!("opened"),
        Err(e) => e,
    }
}

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples")
}

fn still() -> String {
    std::fs::read_to_string(examples().join("cup.toml")).unwrap()
}

fn dir() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

#[test]
fn a_still_design_opens_without_animation() {
    let d = dir();
    let p = d.path().join("a.toml");
    std::fs::write(&p, still()).unwrap();
    let o = open(&p).unwrap();
    assert!(o.animation.is_none());
    assert_eq!(o.design.file, p.display().to_string());
    assert_eq!(o.spec, spec::parse_design(&still()).unwrap());
    // As an animation it is one solved once.
    let a = open_animation(&p).unwrap();
    assert!(matches!(a.animation, Some(Animation::Timed(_))));
}

#[test]
fn a_directory_is_refused_naming_it() {
    let d = dir();
    let e = DesignFile::read(d.path()).unwrap_err();
    assert_eq!(e.kind, OpenErrorKind::NotAFile);
    assert_eq!(
        e.message,
        format!(
            "{}: cannot read the design file: Is a directory",
            d.path().display()
        )
    );
}

#[cfg(unix)]
#[test]
fn a_fifo_is_refused_without_blocking() {
    let d = dir();
    let p = d.path().join("pipe.toml");
    let c = std::ffi::CString::new(p.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    let e = DesignFile::read(&p).unwrap_err();
    assert_eq!(e.kind, OpenErrorKind::NotAFile);
    assert!(e.message.starts_with(&format!("{}: ", p.display())), "{e}");
    assert!(e.message.contains("FIFO"), "{e}");
    assert_eq!(e.message.lines().count(), 1);
    // Through a symlink, the same.
    let l = d.path().join("link.toml");
    std::os::unix::fs::symlink(&p, &l).unwrap();
    let e = fails(open(&l));
    assert_eq!(e.kind, OpenErrorKind::NotAFile);
    assert!(e.message.starts_with(&format!("{}: ", l.display())), "{e}");
}

#[cfg(unix)]
#[test]
fn a_device_is_refused() {
    let e = DesignFile::read(Path::new("/dev/zero")).unwrap_err();
    assert_eq!(e.kind, OpenErrorKind::NotAFile);
    assert!(e.message.starts_with("/dev/zero: "), "{e}");
}

#[test]
fn too_large_a_file_is_refused_naming_it_and_its_size() {
    let d = dir();
    let p = d.path().join("big.toml");
    let f = std::fs::File::create(&p).unwrap();
    f.set_len(MAX_FILE_BYTES + 1).unwrap();
    let e = DesignFile::read_as(&p, "big.toml").unwrap_err();
    assert_eq!(e.kind, OpenErrorKind::TooLarge);
    assert_eq!(
        e.message,
        format!(
            "big.toml: the design file has {} bytes; at most {MAX_FILE_BYTES} (16 MiB) are read",
            MAX_FILE_BYTES + 1
        )
    );
    // One byte less is read (and is then a design error, not a size error).
    f.set_len(MAX_FILE_BYTES).unwrap();
    let e = fails(open(&p));
    assert_ne!(e.kind, OpenErrorKind::TooLarge);
}

#[test]
fn missing_files_and_bad_text_name_the_file() {
    let d = dir();
    let p = d.path().join("none.toml");
    let e = DesignFile::read_as(&p, "none.toml").unwrap_err();
    assert_eq!(
        e.message,
        "none.toml: cannot read the design file: no such file or directory"
    );
    std::fs::write(&p, b"title = \"\xff\"\n").unwrap();
    let e = DesignFile::read_as(&p, "none.toml").unwrap_err();
    assert_eq!(
        e.message,
        "none.toml: the design file is not UTF-8 text (invalid byte at offset 9)"
    );
}

#[test]
fn a_timed_design_and_a_morph_open_as_animations() {
    let o = open(&examples().join("anim/ventricle.toml")).unwrap();
    assert!(matches!(o.animation, Some(Animation::Timed(_))));
    let o = open(&examples().join("anim/glass_morph.toml")).unwrap();
    assert!(matches!(o.animation, Some(Animation::Morph { .. })));
    assert!(o.design.file.ends_with("water_glass.toml") || o.design.file.ends_with(".toml"));
    // A missing source is named.
    let d = dir();
    let m = d.path().join("m.toml");
    std::fs::write(&m, "[morph]\nsource = \"x.toml\"\ntarget = \"b.toml\"\n").unwrap();
    let e = fails(open(&m));
    assert!(
        e.message
            .starts_with(&d.path().join("x.toml").display().to_string()),
        "{e}"
    );
}

#[cfg(unix)]
#[test]
fn read_regular_refuses_special_files_and_reads_no_more_than_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("pipe");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path; mkfifo only creates a file.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    let e = read_regular(&fifo, 100).unwrap_err();
    assert!(matches!(e, ReadError::NotAFile(_)), "{e:?}");
    assert!(e.words().contains("FIFO"), "{}", e.words());
    assert_eq!(e.kind(), OpenErrorKind::NotAFile);
    let e = read_held(dir.path()).unwrap_err();
    assert_eq!(e.words(), "cannot read: Is a directory");
    let f = dir.path().join("ten");
    std::fs::write(&f, b"0123456789").unwrap();
    assert_eq!(read_regular(&f, 10).unwrap(), b"0123456789");
    assert!(matches!(read_regular(&f, 9), Err(ReadError::TooLarge(10))));
    // A file longer than it was when its size was taken is cut one byte past the limit.
    let (file, _) = open_regular(&f).unwrap();
    assert!(matches!(
        read_bounded(file, 4, 4),
        Err(ReadError::TooLarge(5))
    ));
    assert_eq!(read_held(&f).unwrap(), b"0123456789");
}
