//! The log reader's tests: problems named with their line, gzip, memory and file sources.

use super::*;

fn problem_of(text: impl Into<Vec<u8>>) -> (Option<u64>, LogProblem) {
    let src = LogText::new("a.csv", text);
    let mut r = match AccelReader::open(&src) {
        Ok(r) => r,
        Err(e) => return (e.line, e.problem),
    };
    loop {
        match r.next_sample() {
            Ok(Some(_)) => {}
            Ok(None) => panic!("accepted a bad log"),
            Err(e) => return (e.line, e.problem),
        }
    }
}

#[test]
fn reads_rows_in_any_column_order_with_extra_columns() {
    let src = LogText::new(
        "a.csv",
        "\u{feff}temp_c, accel_m_s2 ,t_s\r\n20,1.5,0\n\n21,-2,0.005\n",
    );
    let mut r = AccelReader::open(&src).unwrap();
    let s = r.next_sample().unwrap().unwrap();
    assert_eq!((s.line, s.t_s, s.accel_m_s2), (2, 0.0, 1.5));
    let s = r.next_sample().unwrap().unwrap();
    assert_eq!((s.line, s.t_s, s.accel_m_s2), (4, 0.005, -2.0));
    assert!(r.next_sample().unwrap().is_none());
}

#[test]
fn reads_a_named_axis_column() {
    let src = LogText::new("a.csv", "t_s,ax_m_s2,ay_m_s2\n0,1,2\n0.01,3,4\n");
    let mut r = AccelReader::with_column(&src, "ay_m_s2").unwrap();
    assert_eq!(r.next_sample().unwrap().unwrap().accel_m_s2, 2.0);
    assert_eq!(r.next_sample().unwrap().unwrap().accel_m_s2, 4.0);
    let e = AccelReader::with_column(&src, "az_m_s2").err().unwrap();
    assert!(matches!(
        e.problem,
        LogProblem::MissingColumn {
            column: "az_m_s2",
            ..
        }
    ));
}

#[test]
fn every_problem_names_its_line() {
    assert!(matches!(problem_of(""), (None, LogProblem::Empty { .. })));
    assert!(matches!(
        problem_of("t_s,accel\n0,1\n"),
        (
            Some(1),
            LogProblem::MissingColumn {
                column: "accel_m_s2",
                ..
            }
        )
    ));
    assert!(matches!(
        problem_of("t_s,t_s,accel_m_s2\n"),
        (Some(1), LogProblem::DuplicateColumn { .. })
    ));
    assert!(matches!(
        problem_of("t_s,accel_m_s2\n0,1\n0.1,1,3\n"),
        (
            Some(3),
            LogProblem::FieldCount {
                expected: 2,
                found: 3,
                ..
            }
        )
    ));
    assert!(matches!(
        problem_of("t_s,accel_m_s2\n0,x1\n"),
        (
            Some(2),
            LogProblem::NotANumber {
                column: "accel_m_s2",
                ..
            }
        )
    ));
    for bad in ["NaN", "inf", "-infinity"] {
        assert!(matches!(
            problem_of(format!("t_s,accel_m_s2\n0,1\n{bad},1\n")),
            (Some(3), LogProblem::NotFinite { column: "t_s", .. })
        ));
    }
    assert!(matches!(
        problem_of("t_s,accel_m_s2\n0,1\n0.01,1\n0.01,1\n"),
        (Some(4), LogProblem::NotIncreasing { .. })
    ));
    assert!(matches!(
        problem_of(&b"t_s,accel_m_s2\n0,1\n\xff,1\n"[..]),
        (Some(3), LogProblem::NotText)
    ));
}
