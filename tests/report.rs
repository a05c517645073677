//! End to end: `accelcal report` on a small configuration writes a self-contained page with every
//! section, figure and equation, and a data file; its words follow the verdicts; a failed run
//! leaves an earlier report alone.

mod common;

use accelcal::checks::{CATALOGUE, CheckId};

use std::path::Path;
use std::process::Command;

const SMALL: &str = "[profile]\nduration_s = 6.0\n[ensemble]\nrealizations = 400\n";

const SECTIONS: [&str; 7] = [
    "abstract",
    "introduction",
    "problem",
    "theory",
    "results",
    "conclusions",
    "appendix",
];

/// The case ids of the report, in order.
const CASES: [&str; 3] = ["euler-sample", "analytic-sample", "analytic-interval-mean"];

/// Every figure id of the report.
fn figures() -> Vec<String> {
    let mut ids: Vec<String> = [
        "fig-trajectory",
        "fig-realization",
        "fig-accuracy",
        "fig-mean-error-cases",
    ]
    .map(String::from)
    .to_vec();
    for case in CASES {
        for figure in [
            "mean-error",
            "covariance",
            "orthogonality",
            "whiteness",
            "consistency",
        ] {
            ids.push(format!("fig-{figure}-{case}"));
        }
    }
    ids
}

fn report(dir: &Path, config: &str) -> std::process::Output {
    std::fs::write(dir.join("c.toml"), config).unwrap();
    Command::new(common::bin())
        .args(["report", "--config", "c.toml", "--out", "out", "--quiet"])
        .current_dir(dir)
        .output()
        .unwrap()
}

fn page(dir: &Path) -> String {
    std::fs::read_to_string(dir.join("out/index.html")).unwrap()
}

#[test]
fn report_is_complete_and_self_contained() {
    let dir = tempfile::tempdir().unwrap();
    let o = report(dir.path(), SMALL);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("euler truth") && stdout.contains("analytic truth"),
        "{stdout}"
    );
    let html = page(dir.path());

    // The page parses as XML (the report is written as well-formed, polyglot HTML).
    let doc = roxmltree::Document::parse_with_options(
        &html,
        roxmltree::ParsingOptions {
            allow_dtd: true,
            ..Default::default()
        },
    )
    .expect("index.html parses");
    assert_sections_and_figures(&doc, &html);
    assert_math_and_nothing_outside(&doc, &html);
    assert_verdict_tables(&doc);
    let data = assert_data(dir.path());
    assert_view(dir.path(), &doc, &data);
    assert_numbering(&doc);
}

/// Every section has a heading and words; every figure an SVG with labels and a caption.
fn assert_sections_and_figures(doc: &roxmltree::Document, html: &str) {
    for id in SECTIONS {
        let section = doc
            .descendants()
            .find(|n| n.has_tag_name("section") && n.attribute("id") == Some(id))
            .unwrap_or_else(|| panic!("section {id} missing"));
        assert!(
            section.children().any(|c| c.has_tag_name("h2")),
            "section {id} has no heading"
        );
        let text: String = section.descendants().filter_map(|n| n.text()).collect();
        assert!(
            text.split_whitespace().count() > 20,
            "section {id} is nearly empty"
        );
    }

    for id in figures() {
        let id = id.as_str();
        let figure = doc
            .descendants()
            .find(|n| n.has_tag_name("figure") && n.attribute("id") == Some(id))
            .unwrap_or_else(|| panic!("figure {id} missing"));
        let svg = figure
            .descendants()
            .find(|n| n.has_tag_name("svg"))
            .unwrap_or_else(|| panic!("{id} has no svg"));
        let texts = svg.descendants().filter(|n| n.has_tag_name("text")).count();
        assert!(texts >= 5, "{id}: only {texts} text labels");
        assert!(
            figure.descendants().any(|n| n.has_tag_name("figcaption")),
            "{id} has no caption"
        );
        // Each SVG parses on its own too.
        let src = &html[svg.range()];
        roxmltree::Document::parse(src).unwrap_or_else(|e| panic!("{id}: svg does not parse: {e}"));
        assert!(
            !src.contains("NaN") && !src.contains("inf\""),
            "{id} holds a non-finite number"
        );
    }
}

/// Equations are MathML in the embedded font, and the page needs nothing outside itself.
fn assert_math_and_nothing_outside(doc: &roxmltree::Document, html: &str) {
    // Equations are MathML, set in the embedded math font.
    let maths: Vec<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("math"))
        .collect();
    assert!(maths.len() >= 30, "only {} equations", maths.len());
    assert!(
        maths
            .iter()
            .any(|m| m.descendants().any(|n| n.has_tag_name("mtable"))),
        "no matrix"
    );
    assert!(
        maths
            .iter()
            .any(|m| m.descendants().any(|n| n.has_tag_name("mfrac"))),
        "no fraction"
    );
    assert!(html.contains("@font-face") && html.contains("url(data:font/woff2;base64,"));

    // Nothing outside the page: no address, no external stylesheet, script, image or font.
    for bad in [
        "http:", "https:", "<link", "<script", "@import", "<img", "<iframe", "file:",
    ] {
        assert!(!html.contains(bad), "the page holds {bad:?}");
    }
    assert_eq!(
        html.matches("url(").count(),
        html.matches("url(data:").count(),
        "a url() that is not data:"
    );
    for n in doc.descendants() {
        for a in ["href", "src", "xlink:href"] {
            if let Some(v) = n.attribute(a) {
                assert!(v.starts_with('#'), "{a}={v:?} points outside the page");
            }
        }
    }
}

/// The verdict tables name every check of every case.
fn assert_verdict_tables(doc: &roxmltree::Document) {
    for case in CASES {
        let table = doc
            .descendants()
            .find(|n| n.attribute("id") == Some(&*format!("checks-{case}")))
            .unwrap_or_else(|| panic!("no verdict table for {case}"));
        let text: String = table.descendants().filter_map(|n| n.text()).collect();
        for id in CheckId::ALL {
            assert!(text.contains(id.name()), "{case} table lacks {id:?}");
        }
    }
}

/// data.json: configuration, the realization at the fixes, every ensemble with its summary.
fn assert_data(dir: &Path) -> serde_json::Value {
    let data: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/data.json")).unwrap()).unwrap();
    assert_eq!(data["config"]["profile"]["duration_s"], 6.0);
    assert_eq!(data["realization"]["fixes"].as_array().unwrap().len(), 30);
    let cases: Vec<String> = data["ensembles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| {
            let s = &e["summary"];
            format!(
                "{}-{}",
                s["truth"].as_str().unwrap(),
                s["accelerometer_output"].as_str().unwrap()
            )
        })
        .collect();
    assert_eq!(
        cases,
        ["euler-sample", "analytic-sample", "analytic-interval_mean"]
    );
    for e in data["ensembles"].as_array().unwrap() {
        let s = &e["summary"];
        assert_eq!(s["realizations"], 400);
        assert_eq!(s["checks"].as_array().unwrap().len(), CATALOGUE.len());
        for key in ["position_m", "velocity_m_s", "bias_m_s2"] {
            assert!(s["achieved_rms"][key].as_f64().unwrap() > 0.0, "{key}");
        }
        for key in ["worst_se", "predicted_nees_final"] {
            assert!(s["mean_error_prediction"][key].is_number(), "{key}");
        }
    }

    data
}

/// view.json: what the page shows, as text; its verdicts are data.json's.
fn assert_view(dir: &Path, doc: &roxmltree::Document, data: &serde_json::Value) {
    let page_text: String = doc.descendants().filter_map(|n| n.text()).collect();
    let view: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/view.json")).unwrap()).unwrap();
    let sections = view["sections"].as_array().unwrap();
    let section = |name: &str| {
        sections
            .iter()
            .find(|s| s["section"] == name)
            .unwrap_or_else(|| panic!("view.json has no {name} section"))
    };
    assert_eq!(
        section("theory")["catalogue"].as_array().unwrap().len(),
        CATALOGUE.len()
    );
    let cases: Vec<&serde_json::Value> = section("results")["children"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["section"] == "case")
        .collect();
    assert_eq!(cases.len(), CASES.len());
    for (e, d) in cases.iter().zip(data["ensembles"].as_array().unwrap()) {
        for (row, check) in e["checks"]
            .as_array()
            .unwrap()
            .iter()
            .zip(d["summary"]["checks"].as_array().unwrap())
        {
            assert_eq!(row["id"], check["id"]);
            assert_eq!(row["verdict"], check["verdict"]);
            assert!(page_text.contains(row["what"].as_str().unwrap()));
        }
    }
}

/// Figures and tables are numbered in reading order, from 1, without gaps.
fn assert_numbering(doc: &roxmltree::Document) {
    for (tag, word) in [("figcaption", "Figure"), ("caption", "Table")] {
        let numbers: Vec<usize> = doc
            .descendants()
            .filter(|n| n.has_tag_name(tag))
            .filter_map(|n| {
                let text: String = n.descendants().filter_map(|t| t.text()).collect();
                let rest = text.trim().strip_prefix(word)?.trim_start();
                rest.split('.').next()?.parse().ok()
            })
            .collect();
        let expected: Vec<usize> = (1..=numbers.len()).collect();
        assert_eq!(numbers, expected, "{word} numbers out of reading order");
    }
}

#[test]
fn conclusions_follow_the_verdicts() {
    let dir = tempfile::tempdir().unwrap();
    let mistuned = format!("{SMALL}[filter]\ngps_position_sigma_m = 2.0\n");
    let o = report(dir.path(), &mistuned);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let html = page(dir.path());
    let conclusions =
        &html[html.find("id=\"conclusions\"").unwrap()..html.find("id=\"appendix\"").unwrap()];
    assert!(
        conclusions.contains("With case A (Euler-integrated truth, point samples),")
            && conclusions.contains("does not match the filter"),
        "{conclusions}"
    );
    assert!(
        !conclusions.contains("The filter is consistent with this case"),
        "{conclusions}"
    );
    assert!(
        conclusions.contains("deliberately given statistics that differ"),
        "{conclusions}"
    );
    let abstract_ =
        &html[html.find("id=\"abstract\"").unwrap()..html.find("id=\"introduction\"").unwrap()];
    assert!(
        abstract_.contains("deliberately assumes statistics that differ"),
        "{abstract_}"
    );
    assert!(
        abstract_.contains("the checks detect the mistuning"),
        "{abstract_}"
    );
    assert!(
        abstract_.contains("but achieves RMS errors of"),
        "the σ it quotes are not trustworthy: {abstract_}"
    );

    let o = report(dir.path(), SMALL);
    assert!(o.status.success());
    let html = page(dir.path());
    let conclusions =
        &html[html.find("id=\"conclusions\"").unwrap()..html.find("id=\"appendix\"").unwrap()];
    assert!(
        conclusions.contains("The filter is consistent with"),
        "{conclusions}"
    );
}

/// With no sampled ensembles the sensitivity section says so, and quotes no sampling error.
#[test]
fn a_report_without_sampled_detection_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let o = report(
        dir.path(),
        "[profile]\nduration_s = 2.0\n[ensemble]\nrealizations = 200\n[sensitivity]\ndraws = 0\n",
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let html = page(dir.path());
    assert!(
        html.contains("It is not sampled in this report"),
        "no word on the missing sample"
    );
    assert!(
        !html.contains("√0") && !html.contains(" 0 ensembles"),
        "a sample of none quoted"
    );
}

#[test]
fn a_short_run_quotes_only_times_within_it() {
    let dir = tempfile::tempdir().unwrap();
    let o = report(
        dir.path(),
        "[profile]\nduration_s = 0.4\n[ensemble]\nrealizations = 50\n",
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let html = page(dir.path());
    assert!(
        !html.contains("after 1 s") && !html.contains("after 5 s"),
        "milestones beyond the run"
    );
    assert!(
        html.contains("at the end (0.4 s)"),
        "the end of the run is 0.4 s"
    );
}

#[test]
fn an_output_that_cannot_be_replaced_leaves_the_earlier_report_alone() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir_all(out.join("data.json")).unwrap();
    std::fs::write(out.join("index.html"), "earlier report").unwrap();
    let o = report(dir.path(), SMALL);
    assert_eq!(
        o.status.code(),
        Some(2),
        "an output that cannot be written is the user's to fix, like bad input"
    );
    assert!(String::from_utf8_lossy(&o.stderr).contains("directory"));
    assert_eq!(
        std::fs::read_to_string(out.join("index.html")).unwrap(),
        "earlier report"
    );
    assert_eq!(
        std::fs::read_dir(&out).unwrap().count(),
        2,
        "temporary files left behind"
    );
}

#[test]
fn a_failed_run_leaves_the_earlier_report_alone() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("index.html"), "earlier report").unwrap();
    std::fs::write(out.join("data.json"), "earlier data").unwrap();
    let o = report(dir.path(), "[accelerometer]\nnoise_var_m2_s4 = -1.0\n");
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        std::fs::read_to_string(out.join("index.html")).unwrap(),
        "earlier report"
    );
    assert_eq!(
        std::fs::read_to_string(out.join("data.json")).unwrap(),
        "earlier data"
    );
    assert_eq!(
        std::fs::read_dir(&out).unwrap().count(),
        2,
        "temporary files left behind"
    );
}
