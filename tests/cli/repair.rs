//! End-to-end tests of `streaks train-repair`: training the streak-robust stereo model on a
//! dataset, using it with `streaks disparity --model`, scoring it with `--evaluate`, and the
//! refusals.

use crate::common::TestDir;
use serde_json::Value;

/// `train-repair` writes a model (two classifiers, thresholds, a calibration, provenance) that
/// `disparity --model` applies and `--evaluate` scores; the figures are shares and count the
/// dataset's samples.
#[test]
fn a_model_trained_on_a_dataset_is_used_and_scored() {
    let t = TestDir::new();
    let splits = t.tiny_dataset(Some("images,gt,masks"));
    assert!(splits.len() >= 2, "{splits:?}");
    let (train, val) = (splits[0], splits[1]);
    // A second dataset whose every sample validates.
    t.generate_tiny("more", "2", Some("9"), Some("images,gt,masks"));
    let run = t.streaks(&[
        "train-repair",
        "ds",
        "-o",
        "model.json",
        "--train-split",
        train,
        "--val-split",
        val,
        "--val-dataset",
        "more",
        "--rounds",
        "10",
        "--min-leaf",
        "20",
    ]);
    run.assert_success();
    assert!(run.stderr().contains("phantom holes"), "{}", run.stderr());
    let model: Value =
        serde_json::from_str(&std::fs::read_to_string(t.join("model.json")).unwrap()).unwrap();
    assert_eq!(model["format"], "streaks-repair/1");
    for stage in [&model, &model["context"]] {
        assert_eq!(stage["wrong"]["trees"].as_array().unwrap().len(), 10);
        assert_eq!(stage["streak"]["trees"].as_array().unwrap().len(), 10);
    }
    assert_eq!(
        model["context"]["features"].as_array().unwrap().len(),
        streaks_analysis::repair::CONTEXT_FEATURES.len()
    );
    assert_eq!(model["provenance"]["train_split"], train);
    let val_samples = std::fs::read_to_string(t.join("ds/splits").join(format!("{val}.txt")))
        .unwrap()
        .split_whitespace()
        .count();
    assert_eq!(model["provenance"]["val_samples"], val_samples + 2);
    assert_eq!(model["provenance"]["val_datasets"][0]["seed"], 9);
    let threshold = model["wrong_threshold"].as_f64().unwrap();
    assert!((0.0..=1.0).contains(&threshold), "{threshold}");
    for c in model["calibration"]["kept"]
        .as_array()
        .unwrap()
        .iter()
        .chain(model["calibration"]["repaired"].as_array().unwrap())
    {
        assert!((0.0..=1.0).contains(&c.as_f64().unwrap()), "{c}");
    }
    t.streaks(&[
        "disparity",
        "ds/samples/000000/im0.png",
        "ds/samples/000000/im1.png",
        "-o",
        "d.pfm",
        "--streaks",
        "repair",
        "--model",
        "model.json",
        "--streak-probability",
        "p.pfm",
    ])
    .assert_success();
    assert!(t.join("d_confidence.pfm").is_file() && t.join("d_streaks.png").is_file());
    // The streak mask is the probability map thresholded at the model's thresholds.
    let grow = model["streak_grow_threshold"].as_f64().map(|g| g as f32);
    let streak_threshold = model["streak_threshold"].as_f64().unwrap() as f32;
    let p = streaks_image::pfm::read_pfm(&t.join("p.pfm")).unwrap();
    let mask = streaks_image::GrayImage::load(&t.join("d_streaks.png")).unwrap();
    assert!(p.data.iter().all(|v| (0.0..=1.0).contains(v)));
    let want = streaks_analysis::streak_classifier::streak_mask(&p, streak_threshold, grow);
    assert_eq!(
        mask.data.iter().map(|&m| m > 0.0).collect::<Vec<_>>(),
        want.data.iter().map(|&m| m > 0.0).collect::<Vec<_>>()
    );
    let evaluate = |splits: &str| {
        let run = t.streaks(&[
            "train-repair",
            "--evaluate",
            "ds",
            "--model",
            "model.json",
            "--val-split",
            splits,
            "-o",
            "figures.json",
        ]);
        run.assert_success();
        assert!(run.stderr().contains("phantom holes"), "{}", run.stderr());
    };
    evaluate("all");
    let f: Value =
        serde_json::from_str(&std::fs::read_to_string(t.join("figures.json")).unwrap()).unwrap();
    assert_eq!(f["samples"], 6);
    // A split that the dataset leaves empty adds nothing to a list of splits.
    let empty = ["train", "val", "test"]
        .into_iter()
        .find(|s| !splits.contains(s))
        .unwrap_or_else(|| {
            std::fs::write(t.join("ds/splits").join(format!("{}.txt", splits[2])), "").unwrap();
            splits[2]
        });
    evaluate(&format!("{val},{empty}"));
    for key in [
        "phantom_holes_sgm",
        "phantom_holes",
        "off_road_bad2",
        "missing_or_wrong",
        "road_density",
    ] {
        let v = f[key].as_f64().unwrap();
        assert!((0.0..=1.0).contains(&v), "{key} {v}");
    }
    // Every pixel with a truth is counted once: 6 samples of 96x64, less the sky.
    let truth = f["counts"]["truth"].as_u64().unwrap();
    assert!(truth > 0 && truth <= 6 * 96 * 64, "{truth}");
    assert_eq!(
        f["counts"]["road"].as_u64().unwrap() + f["counts"]["off"].as_u64().unwrap(),
        truth
    );
}

/// The refusals: one split for both, a folder that is neither a dataset nor a pair, one
/// dataset that would both train and validate, training without `-o`.
#[test]
fn bad_arguments_are_refused_with_their_reason() {
    let t = TestDir::new();
    std::fs::create_dir(t.join("empty")).unwrap();
    t.streaks(&[
        "train-repair",
        "empty",
        "-o",
        "m.json",
        "--val-split",
        "train",
    ])
    .assert_failure_mentioning("must differ");
    t.streaks(&["train-repair", "--evaluate", "empty"])
        .assert_failure_mentioning("neither a dataset");
    t.streaks(&[
        "train-repair",
        "empty",
        "-o",
        "m.json",
        "--val-dataset",
        "./empty",
    ])
    .assert_failure_mentioning("both a training dataset and a validation dataset");
    t.streaks(&["train-repair", "empty"])
        .assert_failure_mentioning("--output");
    t.streaks(&["train-repair", "empty", "-o", "m.json"])
        .assert_failure_mentioning("not a dataset folder");
    assert!(!t.join("m.json").exists());
}
