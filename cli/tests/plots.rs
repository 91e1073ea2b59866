//! `eomgen simulate --plot`: SVG or PNG by the extension, axes with units, tick labels, a
//! legend entry per joint, the velocity, effort and energy plots beside, byte-identical output
//! for the same run, and a one-line error (writing nothing) for any other extension.

use crate::support;

use std::path::Path;

use support::{eomgen, listing, one_line_error, robot, scratch, stdout_of};

/// The text of every `<text>` element of an SVG, trimmed.
fn texts(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| t.split_once('>'))
        .filter_map(|(_, rest)| rest.split_once("</text>"))
        .map(|(text, _)| text.trim().to_string())
        .collect()
}

fn ur5_run(plot: &Path, extra: &[&str]) -> String {
    let urdf = robot("ur5");
    let mut args = vec![
        "simulate",
        urdf.to_str().unwrap(),
        "--duration",
        "0.2",
        "--q0",
        "0.1,-1.2,1.4,-1,-1.5,0.3",
        "--plot",
        plot.to_str().unwrap(),
    ];
    args.extend(extra);
    stdout_of(&args)
}

const UR5_JOINTS: [&str; 6] = [
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
];

/// Whether `text` is a number as a tick label shows it.
fn is_number(text: &str) -> bool {
    text.parse::<f64>().is_ok()
}

#[test]
fn svg_plots_have_titles_axes_with_units_ticks_and_a_legend() {
    let (_guard, dir) = scratch("plots-svg");
    let plot = dir.join("ur5.svg");
    ur5_run(
        &plot,
        &[
            "--controller",
            "computed-torque",
            "--target",
            "0.3,-1,1.2,-0.8,-1.3,0.5",
        ],
    );
    assert_eq!(
        listing(&dir),
        [
            "ur5-efforts.svg",
            "ur5-energy.svg",
            "ur5-velocities.svg",
            "ur5.svg"
        ]
    );
    for (file, title, y_label) in [
        ("ur5.svg", "ur5: joint positions", "position (rad)"),
        (
            "ur5-velocities.svg",
            "ur5: joint velocities",
            "velocity (rad/s)",
        ),
        (
            "ur5-efforts.svg",
            "ur5: joint efforts of the controller",
            "effort (N m)",
        ),
    ] {
        let svg = std::fs::read_to_string(dir.join(file)).unwrap();
        assert!(svg.starts_with("<svg "), "{file}");
        assert!(svg.trim_end().ends_with("</svg>"), "{file}");
        let texts = texts(&svg);
        for wanted in [title, y_label, "time (s)"] {
            assert!(
                texts.iter().any(|t| t == wanted),
                "{file}: no {wanted} in {texts:?}"
            );
        }
        // Tick labels on both axes: the time axis starts at 0 and ends at 0.20.
        assert!(
            texts.iter().filter(|t| is_number(t)).count() >= 8,
            "{texts:?}"
        );
        assert!(texts.iter().any(|t| t == "0.20"), "{texts:?}");
        // The legend names every joint once, in order.
        let legend: Vec<&str> = texts
            .iter()
            .map(String::as_str)
            .filter(|t| UR5_JOINTS.contains(t))
            .collect();
        assert_eq!(legend, UR5_JOINTS, "{file}");
        // A light grid: grey lines.
        assert!(
            svg.matches("<line opacity=\"1\" stroke=\"#D7D7D7\"")
                .count()
                >= 8
        );
    }
    let energy = std::fs::read_to_string(dir.join("ur5-energy.svg")).unwrap();
    let texts = texts(&energy);
    assert!(
        texts.contains(&"ur5: energy (controlled run: not conserved by design)".to_string()),
        "{texts:?}"
    );
    assert!(texts.contains(&"relative energy change (E - E0) / |E0|".to_string()));
    assert!(texts.contains(&"(E - E0) / |E0|".to_string()), "the legend");
}

#[test]
fn a_free_run_plots_the_drift_of_the_integrator_and_mixed_joints_say_rad_or_m() {
    let (_guard, dir) = scratch("plots-free");
    let plot = dir.join("panda.svg");
    stdout_of(&[
        "simulate",
        robot("panda").to_str().unwrap(),
        "--duration",
        "0.05",
        "--plot",
        plot.to_str().unwrap(),
    ]);
    let read = |file: &str| texts(&std::fs::read_to_string(dir.join(file)).unwrap());
    assert!(read("panda.svg").contains(&"position (rad or m)".to_string()));
    assert!(read("panda-velocities.svg").contains(&"velocity (rad/s or m/s)".to_string()));
    let efforts = read("panda-efforts.svg");
    assert!(efforts.contains(&"effort (N m or N)".to_string()));
    assert!(efforts.contains(&"panda: joint efforts (no controller: none applied)".to_string()));
    let energy = read("panda-energy.svg");
    assert!(
        energy.contains(&"panda: energy drift of RK4 (dt = 0.001 s)".to_string()),
        "{energy:?}"
    );
}

#[test]
fn the_same_run_gives_the_same_bytes() {
    let (_guard, dir) = scratch("plots-same");
    let (a, b) = (dir.join("a.svg"), dir.join("b.svg"));
    ur5_run(&a, &[]);
    ur5_run(&b, &[]);
    for suffix in ["", "-velocities", "-efforts", "-energy"] {
        let read = |stem: &str| std::fs::read(dir.join(format!("{stem}{suffix}.svg"))).unwrap();
        assert!(read("a") == read("b"), "{suffix}");
    }
    let (a, b) = (dir.join("a.png"), dir.join("b.png"));
    ur5_run(&a, &[]);
    ur5_run(&b, &[]);
    assert!(std::fs::read(a).unwrap() == std::fs::read(b).unwrap());
}

#[test]
fn png_plots_are_pngs_of_960_by_540() {
    let (_guard, dir) = scratch("plots-png");
    let plot = dir.join("ur5.PNG");
    ur5_run(&plot, &[]);
    assert_eq!(
        listing(&dir),
        [
            "ur5-efforts.PNG",
            "ur5-energy.PNG",
            "ur5-velocities.PNG",
            "ur5.PNG"
        ]
    );
    for name in listing(&dir) {
        let png = std::fs::read(dir.join(&name)).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "{name}");
        assert_eq!(&png[12..16], b"IHDR", "{name}");
        let be = |at: usize| u32::from_be_bytes(png[at..at + 4].try_into().unwrap());
        assert_eq!((be(16), be(20)), (960, 540), "{name}");
        // 8-bit RGB, compressed: more than a blank page, less than the raw pixels.
        assert_eq!((png[24], png[25]), (8, 2), "{name}");
        assert!(
            (10_000..960 * 540 * 3).contains(&png.len()),
            "{name}: {}",
            png.len()
        );
        assert_eq!(&png[png.len() - 8..png.len() - 4], b"IEND", "{name}");
    }
}

#[test]
fn another_extension_is_a_one_line_error_before_the_run() {
    let (_guard, dir) = scratch("plots-bad");
    for name in ["ur5.pdf", "ur5", "ur5.svg.txt"] {
        let plot = dir.join(name);
        let err = one_line_error(&eomgen(&[
            "simulate",
            robot("ur5").to_str().unwrap(),
            "--plot",
            plot.to_str().unwrap(),
        ]));
        assert!(err.contains(plot.to_str().unwrap()), "{err}");
        assert!(err.contains(".svg or .png"), "{err}");
    }
    assert!(listing(&dir).is_empty(), "{:?}", listing(&dir));
}

#[test]
fn every_sample_of_every_joint_is_a_point_of_its_line() {
    let (_guard, dir) = scratch("plots-lines");
    let file = dir.join("ur5.svg");
    ur5_run(&file, &[]);
    let svg = std::fs::read_to_string(&file).unwrap();
    assert!(svg.starts_with("<svg ") && svg.contains("xmlns=\"http://www.w3.org/2000/svg\""));
    assert!(svg.trim_end().ends_with("</svg>"));
    let joints = UR5_JOINTS;
    // The data lines are the polylines 2 px wide (the axes' are 1 px, the legend's 3 px).
    let lines: Vec<&str> = svg
        .lines()
        .filter(|l| l.starts_with("<polyline") && l.contains("stroke-width=\"2\""))
        .collect();
    assert_eq!(lines.len(), joints.len(), "one trajectory per joint");
    for line in lines {
        let points = line
            .split("points=\"")
            .nth(1)
            .unwrap()
            .trim_end_matches("\"/>")
            .trim_end();
        let xy: Vec<(f64, f64)> = points
            .split(' ')
            .map(|p| {
                let (x, y) = p.split_once(',').unwrap();
                (x.parse().unwrap(), y.parse().unwrap())
            })
            .collect();
        // Every sample (200 steps and the initial state), inside the 960 x 540 picture, in
        // time order (whole pixels: neighbours may share one).
        assert_eq!(xy.len(), 201);
        assert!(xy.windows(2).all(|w| w[1].0 >= w[0].0));
        assert!(xy[200].0 > xy[0].0 + 500.0);
        assert!(xy
            .iter()
            .all(|&(x, y)| (0.0..=960.0).contains(&x) && (0.0..=540.0).contains(&y)));
    }
}

#[test]
fn a_damped_run_says_energy_is_not_conserved() {
    let (_guard, dir) = scratch("plots-damped");
    let plot = dir.join("dp.svg");
    stdout_of(&[
        "simulate",
        robot("double_pendulum").to_str().unwrap(),
        "--friction",
        "--duration",
        "0.2",
        "--q0",
        "1.8,1.2",
        "--plot",
        plot.to_str().unwrap(),
    ]);
    let energy = texts(&std::fs::read_to_string(dir.join("dp-energy.svg")).unwrap());
    assert!(
        energy.contains(&"2dof_planar: energy (damped run: not conserved by design)".to_string()),
        "{energy:?}"
    );
}
