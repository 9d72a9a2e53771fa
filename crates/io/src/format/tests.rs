use super::*;
use std::str::FromStr;

#[test]
fn every_format_round_trips_through_its_name_and_its_path() {
    for f in OutputFormat::ALL {
        assert_eq!(f.to_string().parse::<OutputFormat>().unwrap(), f);
        assert_eq!(OutputFormat::from_str(&f.name().to_uppercase()).unwrap(), f);
        let p = format!("dir.v2/part.{f}");
        assert_eq!(OutputFormat::from_path(Path::new(&p)).unwrap(), f, "{p}");
        let p = format!("PART.{}", f.name().to_uppercase());
        assert_eq!(OutputFormat::from_path(Path::new(&p)).unwrap(), f, "{p}");
        match f.mesh() {
            Ok(m) => {
                assert!(!f.is_cad());
                assert_eq!(OutputFormat::from(m), f);
                assert_eq!(m.extension(), f.name());
                assert_eq!(
                    mesh::Format::from_path(Path::new(&format!("a.{f}"))).unwrap(),
                    m
                );
            }
            Err(e) => {
                assert!(f.is_cad());
                assert!(e.to_string().contains("unknown output extension"), "{e}");
            }
        }
    }
    assert_eq!("stp".parse::<OutputFormat>().unwrap(), OutputFormat::Step);
    assert_eq!("IGES".parse::<OutputFormat>().unwrap(), OutputFormat::Iges);
    assert_eq!(".glb".parse::<OutputFormat>().unwrap(), OutputFormat::Glb);
}

#[test]
fn unknown_formats_are_refused_with_the_mesh_writers_words() {
    let all = "use .obj, .stl, .ply, .glb, .csv, .step, .stp, .igs or .iges";
    let e = "xyz".parse::<OutputFormat>().unwrap_err();
    assert_eq!(
        e.to_string(),
        format!("unknown output extension '.xyz': {all}")
    );
    let e = OutputFormat::from_path(Path::new("out")).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!("output path 'out' has no extension: {all}")
    );
    // The list is the formats' own: every extension of every format is in it.
    for f in OutputFormat::ALL {
        for ext in f.extensions() {
            assert!(all.contains(&format!(".{ext}")), "{ext}");
        }
    }
    assert_eq!(extensions_hint(&OutputFormat::ALL), all);
    // A typo gets the nearest extension.
    let e = OutputFormat::from_path(Path::new("part.stpe")).unwrap_err();
    assert!(
        e.to_string().contains("'.stpe' (did you mean .step?)"),
        "{e}"
    );
    assert!("".parse::<OutputFormat>().is_err());
    // The mesh writers keep refusing CAD extensions as they always did, in the user's words.
    let e = mesh::Format::from_path(Path::new("a.STP")).unwrap_err();
    assert_eq!(
        e.to_string(),
        "unknown output extension '.STP': use .obj, .stl, .ply, .glb or .csv"
    );
}

#[test]
fn sizes_are_positive_and_within_the_picture_limits() {
    assert_eq!(parse_size("800x600").unwrap(), (800, 600));
    assert_eq!(parse_size(" 16 X 9 ").unwrap(), (16, 9));
    let max = crate::render::MAX_SIDE;
    assert_eq!(parse_size(&format!("{max}x1")).unwrap(), (max, 1));
    for bad in ["1x0", "0x1", "x", "800", "800x", "-1x5", "1.5x2", "axb", ""] {
        assert!(parse_size(bad).is_err(), "{bad}");
    }
    let e = parse_size(&format!("{}x10", max + 1)).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!(
            "width and height must be between 1 and {max} (got {}x10)",
            max + 1
        )
    );
    assert!("1x0".parse::<PictureSize>().is_err());
    assert_eq!(
        "3x4".parse::<PictureSize>().unwrap(),
        PictureSize {
            width: 3,
            height: 4
        }
    );
}

#[test]
fn source_date_epoch_is_honoured() {
    assert_eq!(timestamp_from(Some("0")), 0);
    assert_eq!(timestamp_from(Some("1700000000")), 1_700_000_000);
    // Unset or not a whole number: the current time (after 2020).
    assert!(timestamp_from(None) > 1_577_836_800);
    assert!(timestamp_from(Some("soon")) > 1_577_836_800);
}

#[test]
fn extensions_are_compared_without_case() {
    assert!(has_extension(Path::new("a.GLB"), "glb"));
    assert!(!has_extension(Path::new("a.glb.txt"), "glb"));
    assert!(!has_extension(Path::new("glb"), "glb"));
}

#[test]
fn step_and_iges_record_the_timestamp_they_are_given() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/cup.toml");
    let text = &std::fs::read_to_string(path).unwrap();
    let spec = crate::spec::parse_design(text).unwrap();
    let solved = crate::design::solve_design(&spec).unwrap();
    let model = crate::cad::approximate_design(&solved, 1e-2).unwrap();
    let units = crate::spec::Units::Millimetre;
    let seconds = timestamp_from(Some("86400"));
    let step = write_cad(&model, OutputFormat::Step, units, "a.step", seconds).unwrap();
    assert!(step.contains("1970-01-02T00:00:00"), "{}", &step[..400]);
    let iges = write_cad(&model, OutputFormat::Iges, units, "a.igs", seconds).unwrap();
    assert!(iges.contains("700102.000000"), "{}", &iges[..400]);
    assert!(write_cad(&model, OutputFormat::Obj, units, "a.obj", seconds).is_err());
}

#[test]
fn units_read_and_print_as_the_design_file_writes_them() {
    use crate::spec::Units;
    for u in [
        Units::Millimetre,
        Units::Centimetre,
        Units::Metre,
        Units::Inch,
    ] {
        assert_eq!(u.to_string().parse::<Units>().unwrap(), u);
        assert!((u.millimetres() - 1e3 * u.metres()).abs() < 1e-12);
    }
    assert_eq!(" Inch ".parse::<Units>().unwrap(), Units::Inch);
    assert_eq!(
        "furlong".parse::<Units>().unwrap_err().to_string(),
        "unknown length unit `furlong` (mm, cm, m or in)"
    );
}
