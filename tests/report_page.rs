//! `fem-forms report`: the page is well formed HTML (html5ever's parser through
//! `scraper`), every chart's drawing gives back the numbers of the data file beside it,
//! the accuracy table holds the exact solution's values, and, where Chromium is
//! installed, a real browser renders every chart with no console message.

use fem_forms::report_page::{self, Options};
use scraper::{ElementRef, Html, Selector};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The page of two beam scenes' studies, written once for every test here.
fn page() -> &'static (PathBuf, String) {
    static PAGE: OnceLock<(PathBuf, String)> = OnceLock::new();
    PAGE.get_or_init(|| {
        let out = std::env::temp_dir().join(format!("fem-forms-report-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&out);
        let options = Options {
            full: false,
            out: out.clone(),
            scenes: vec!["bernoulli-flat".into(), "timoshenko-a".into()],
            petsc_ex9: None,
        };
        let path = report_page::write(&options).expect("the report");
        assert_eq!(path, out.join("index.html"));
        let text = std::fs::read_to_string(&path).unwrap();
        (out, text)
    })
}

fn select<'a>(element: ElementRef<'a>, selector: &str) -> Vec<ElementRef<'a>> {
    let selector = Selector::parse(selector).unwrap();
    element.select(&selector).collect()
}

#[test]
fn the_page_is_well_formed_html_with_a_section_per_family_and_every_study() {
    let (_, text) = page();
    let document = Html::parse_document(text);
    assert!(
        document.errors.is_empty(),
        "parse errors: {:?}",
        &document.errors[..document.errors.len().min(5)]
    );
    let root = document.root_element();
    // one family (both scenes are beams), its nine studies, each with what it checks
    assert_eq!(select(root, "section").len(), 1);
    assert_eq!(select(root, "section#family-beam").len(), 1);
    let headings: Vec<String> = select(root, "section h3")
        .iter()
        .map(|h| h.text().collect())
        .collect();
    for study in [
        "bernoulli-flat: convergence",
        "bernoulli-flat: stability",
        "bernoulli-flat: alpha",
        "bernoulli-flat: work-precision",
        "bernoulli-flat: iterations",
        "bernoulli-flat: adaptivity",
        "timoshenko-a: locking",
        "timoshenko-a: stability",
        "timoshenko-a: iterations",
    ] {
        assert!(
            headings.iter().any(|h| h == study),
            "{study} in {headings:?}"
        );
    }
    assert!(select(root, "p.failed").is_empty(), "a part failed");
    for checks in select(root, "p.checks") {
        assert!(checks.text().collect::<String>().len() > 40);
    }
    // self-contained: nothing fetched from elsewhere
    for tag in ["img", "link", "iframe", "script[src]"] {
        assert!(select(root, tag).is_empty(), "a <{tag}> on the page");
    }
    // the run's facts: a commit (this is a checkout) and the date
    let facts: Vec<String> = select(root, "table.facts td")
        .iter()
        .map(|c| c.text().collect())
        .collect();
    assert!(facts[0].ends_with(" UTC"), "{facts:?}");
    let hash = facts[1].split([' ', ',']).next().unwrap_or("");
    assert!(
        hash.len() == 40 && hash.chars().all(|c| c.is_ascii_hexdigit()),
        "no commit hash in {facts:?}"
    );
}

/// The numbers of a chart's data file, by (panel, curve): each curve's points in order.
type ChartData = Vec<((usize, String), Vec<(f64, f64)>)>;

/// Reads a `.chart.csv` (fields quoted where they hold a comma).
fn read_chart_data(path: &Path) -> ChartData {
    let text = std::fs::read_to_string(path).unwrap();
    let mut data: ChartData = Vec::new();
    for line in text.lines().skip(1) {
        let mut fields = Vec::new();
        let mut field = String::new();
        let mut quoted = false;
        let mut chars = line.chars().peekable();
        while let Some(c) = chars.next() {
            match c {
                '"' if quoted && chars.peek() == Some(&'"') => {
                    field.push('"');
                    chars.next();
                }
                '"' => quoted = !quoted,
                ',' if !quoted => fields.push(std::mem::take(&mut field)),
                c => field.push(c),
            }
        }
        fields.push(field);
        assert_eq!(fields.len(), 4, "{line}");
        let key = (fields[0].parse().unwrap(), fields[1].clone());
        let point = (fields[2].parse().unwrap(), fields[3].parse().unwrap());
        match data.last_mut() {
            Some((k, points)) if *k == key => points.push(point),
            _ => data.push((key, vec![point])),
        }
    }
    data
}

/// The axis mapping of a panel: (pixel start, pixel end, value at start, at end, log).
fn axis(pixels: (f64, f64), spec: &str) -> (f64, f64, f64, f64, bool) {
    let parts: Vec<&str> = spec.split_whitespace().collect();
    (
        pixels.0,
        pixels.1,
        parts[0].parse().unwrap(),
        parts[1].parse().unwrap(),
        parts[2] == "log",
    )
}

/// The value at pixel `p` of an axis, and the tolerance of a value read back (a
/// hundred-thousandth of the axis, in log units on a log axis).
fn value_at(p: f64, (start, end, lo, hi, log): (f64, f64, f64, f64, bool)) -> f64 {
    let f = (p - start) / (end - start);
    if log {
        (lo.ln() + f * (hi.ln() - lo.ln())).exp()
    } else {
        lo + f * (hi - lo)
    }
}

fn close(a: f64, b: f64, (_, _, lo, hi, log): (f64, f64, f64, f64, bool)) -> bool {
    if log {
        (a.ln() - b.ln()).abs() <= 1e-5 * (hi / lo).ln()
    } else {
        (a - b).abs() <= 1e-5 * (hi - lo).abs()
    }
}

#[test]
fn every_chart_draws_the_numbers_of_the_data_file_beside_it() {
    let (out, text) = page();
    let document = Html::parse_document(text);
    let figures = select(document.root_element(), "figure[data-csv]");
    assert!(figures.len() >= 12, "{} charts with data", figures.len());
    let mut points_checked = 0;
    for figure in figures {
        let csv = figure.value().attr("data-csv").unwrap();
        let data = read_chart_data(&out.join(csv));
        let mut drawn: ChartData = Vec::new();
        let mut axes = Vec::new();
        for (k, panel) in select(figure, "g.panel").into_iter().enumerate() {
            let attr = |name: &str| panel.value().attr(name).unwrap().to_string();
            let bounds: Vec<f64> = attr("data-box")
                .split_whitespace()
                .map(|v| v.parse().unwrap())
                .collect();
            let x = axis((bounds[0], bounds[2]), &attr("data-x"));
            // the y axis runs upwards: its start is the box's bottom
            let y = axis((bounds[3], bounds[1]), &attr("data-y"));
            for series in select(panel, "g.series") {
                let name = series.value().attr("data-name").unwrap().to_string();
                let line = select(series, "polyline.data")[0];
                let points: Vec<(f64, f64)> = line
                    .value()
                    .attr("points")
                    .unwrap()
                    .split_whitespace()
                    .map(|p| {
                        let (px, py) = p.split_once(',').unwrap();
                        (
                            value_at(px.parse().unwrap(), x),
                            value_at(py.parse().unwrap(), y),
                        )
                    })
                    .collect();
                if !points.is_empty() {
                    drawn.push(((k + 1, name), points));
                    axes.push((x, y));
                }
            }
        }
        assert_eq!(
            drawn.iter().map(|d| &d.0).collect::<Vec<_>>(),
            data.iter().map(|d| &d.0).collect::<Vec<_>>(),
            "{csv}: the curves drawn and those of the data file"
        );
        for ((drawn, data), (x, y)) in drawn.iter().zip(&data).zip(&axes) {
            assert_eq!(drawn.1.len(), data.1.len(), "{csv} {:?}", drawn.0);
            for (a, b) in drawn.1.iter().zip(&data.1) {
                assert!(
                    close(a.0, b.0, *x) && close(a.1, b.1, *y),
                    "{csv} {:?}: drawn at {a:?}, the file has {b:?}",
                    drawn.0
                );
                points_checked += 1;
            }
        }
    }
    assert!(points_checked > 100, "{points_checked} points");
}

#[test]
fn the_accuracy_table_holds_the_exact_solutions_values() {
    let (_, text) = page();
    let document = Html::parse_document(text);
    let rows = select(document.root_element(), "table.accuracy tr");
    let cells = |row: &ElementRef| -> Vec<String> {
        select(*row, "td")
            .iter()
            .map(|c| c.text().collect())
            .collect()
    };
    // bernoulli-flat at its studies' load q = 100 touches its obstacle on an interval:
    // ∫λ against the exact solution's
    let force = rows
        .iter()
        .map(cells)
        .find(|c| c.len() == 7 && c[0] == "bernoulli-flat" && c[2].starts_with("contact force"))
        .expect("bernoulli-flat's contact force row");
    let computed: f64 = force[3].parse().unwrap();
    let reference: f64 = force[4].parse().unwrap();
    let relative: f64 = force[5].parse().unwrap();
    assert!(reference > 1.0, "{force:?}");
    assert!((computed - reference).abs() / reference < 1e-3, "{force:?}");
    assert!(relative < 1e-3, "{force:?}");
    assert!(force[6].contains("exact solution"), "{force:?}");
}

/// Chromium headless, where installed (`.ci/run` installs it): the page's own check
/// finds a drawing in every chart, nothing is written to the console, and a screenshot
/// is saved beside the page.
#[test]
fn a_headless_browser_renders_every_chart_without_console_messages() {
    let Some(chromium) = ["chromium", "chromium-browser", "google-chrome"]
        .into_iter()
        .find(|c| {
            std::process::Command::new(c)
                .arg("--version")
                .output()
                .is_ok_and(|o| o.status.success())
        })
    else {
        eprintln!("skipped: no Chromium installed (.ci/run installs it)");
        return;
    };
    let (out, text) = page();
    let charts = Html::parse_document(text)
        .root_element()
        .select(&Selector::parse("figure svg").unwrap())
        .count();
    let url = format!("file://{}", out.join("index.html").display());
    let browser = |profile: &str, args: &[&str]| {
        std::process::Command::new(chromium)
            .args([
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--disable-quic",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                "--enable-logging=stderr",
                "--v=0",
                "--virtual-time-budget=10000",
            ])
            .arg(format!("--user-data-dir={}", out.join(profile).display()))
            .args(args)
            .arg(&url)
            .output()
            .expect("chromium runs")
    };
    let dump = browser("profile-dom", &["--dump-dom"]);
    let dom = String::from_utf8_lossy(&dump.stdout);
    let stderr = String::from_utf8_lossy(&dump.stderr);
    let console: Vec<&str> = stderr.lines().filter(|l| l.contains(":CONSOLE")).collect();
    assert!(console.is_empty(), "console: {console:?}");
    let check = Html::parse_document(&dom);
    let result = check
        .root_element()
        .select(&Selector::parse("#render-check").unwrap())
        .next()
        .expect("the render check");
    assert_eq!(
        result.value().attr("data-charts"),
        Some(charts.to_string().as_str()),
        "{}",
        result.text().collect::<String>()
    );
    assert_eq!(result.value().attr("data-empty"), Some(""));
    let shot = out.join("screenshot.png");
    let screenshot = browser(
        "profile-shot",
        &[
            &format!("--screenshot={}", shot.display()),
            "--window-size=1200,3000",
        ],
    );
    assert!(screenshot.status.success());
    let size = std::fs::metadata(&shot).map_or(0, |m| m.len());
    assert!(size > 10_000, "screenshot of {size} bytes");
    eprintln!("screenshot: {}", shot.display());
}

/// What ex9 prints is read back, and a diverged ex9 (which exits 0) is an error.
#[test]
fn ex9s_output_is_read_and_its_divergence_refused() {
    let printed = "errors on 17 x 17 grid:  av |u-uexact|  = 2.707e-03,  |u-uexact|_inf = 1.428e-02\n\
        Time (sec):           9.001e-02     1.000   9.001e-02\n\
        SNESSolve              5 1.0 7.0732e-02 1.0 1.69e+07 1.0 0.0e+00 0.0e+00 0.0e+00 79 100  0  0  0  79 100  0  0  0   239\n";
    let run = report_page::parse_ex9(16, printed).unwrap();
    assert_eq!(
        (run.size, run.mean, run.max, run.seconds),
        (16, 2.707e-3, 1.428e-2, 7.0732e-2)
    );
    let diverged =
        format!("Nonlinear solve did not converge due to DIVERGED_MAX_IT iterations 50\n{printed}");
    let error = report_page::parse_ex9(16, &diverged).unwrap_err();
    assert!(
        error.contains("DIVERGED_MAX_IT") && error.contains("17²"),
        "{error}"
    );
    assert!(report_page::parse_ex9(16, "nothing").is_err());
}

/// Where a built ex9 is given (`FEM_FORMS_PETSC_EX9`; `.ci/run` builds it when PETSc is
/// installed): run beside the nodal method, it prints the same errors to its four
/// digits on every grid (the same discrete problem, solved independently).
#[test]
fn petscs_ex9_run_now_agrees_with_the_nodal_method() {
    let Some(ex9) = std::env::var_os("FEM_FORMS_PETSC_EX9").map(PathBuf::from) else {
        eprintln!("skipped: FEM_FORMS_PETSC_EX9 names no built ex9");
        return;
    };
    let out = std::env::temp_dir().join(format!("fem-forms-report-ex9-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let options = Options {
        full: false,
        out: out.clone(),
        scenes: vec!["membrane-lshape".into()],
        petsc_ex9: Some(ex9),
    };
    report_page::write(&options).expect("the report");
    let table = std::fs::read_to_string(
        out.join("studies/membrane-radial-petsc-ex9/membrane-radial-petsc-ex9.csv"),
    )
    .unwrap();
    let mut grids = 0;
    for line in table.lines().skip(1) {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        for (ours, theirs) in [(v[1], v[2]), (v[3], v[4])] {
            assert_eq!(
                format!("{ours:.3e}"),
                format!("{theirs:.3e}"),
                "N = {}",
                v[0]
            );
        }
        grids += 1;
    }
    assert_eq!(grids, 5);
}

/// The beams' convergence is charted against the cell length 1/N (it once took the
/// spacing of the plot's samples, h/8).
#[test]
fn beam_convergence_is_against_the_cell_length() {
    let (out, _) = page();
    let csv = std::fs::read_to_string(
        out.join("studies/bernoulli-flat-convergence/bernoulli-flat-convergence.csv"),
    )
    .unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let mut rows = 0;
    for line in csv.lines().skip(1) {
        let cells: Vec<&str> = line.split(',').collect();
        let size: f64 = cells[column("size")].parse().unwrap();
        let h: f64 = cells[column("h")].parse().unwrap();
        assert!((h * size - 1.0).abs() < 1e-12, "{line}");
        rows += 1;
    }
    assert!(rows >= 3, "{csv}");
}
