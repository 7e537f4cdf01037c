//! End-to-end tests of `streaks detect` and `streaks train-detector`: the hand-built detector on
//! an image with a known streak (mask written and scored), the learned one over a tiny
//! generated dataset (per-sample and pooled counts that agree with the dataset's own masks), a
//! classifier trained on a dataset and used, and bad input that fails clearly without writing.

use crate::common::TestDir;
use serde_json::Value;
use streaks_image::GrayImage;

/// Non-zero pixels of a mask PNG (`and`: only where this mask is non-zero too).
fn count(path: &std::path::Path, and: Option<&std::path::Path>) -> u64 {
    let m = GrayImage::load(path).unwrap();
    let a = and.map(|p| GrayImage::load(p).unwrap());
    (0..m.data.len())
        .filter(|&i| m.data[i] > 0.0 && a.as_ref().is_none_or(|a| a.data[i] > 0.0))
        .count() as u64
}

/// A 160 x 120 night road: dark, a vertical streak (Gaussian, sigma 3.5 px) at x = 80 from row
/// 70 down, a lamp above it at row 30. Returns the image and the streak's half-maximum truth.
fn streak_image() -> (GrayImage, GrayImage) {
    let (w, h) = (160, 120);
    let mut img = GrayImage::new(w, h, 0.0).unwrap();
    let mut truth = GrayImage::new(w, h, 0.0).unwrap();
    for y in 0..h {
        for x in 0..w {
            let (xc, yc) = (x as f32 + 0.5, y as f32 + 0.5);
            let dx = xc - 80.0;
            let s = if yc > 70.0 {
                0.5 * (-dx * dx / (2.0 * 3.5 * 3.5)).exp()
            } else {
                0.0
            };
            let r2 = dx * dx + (yc - 30.0).powi(2);
            let lamp = (-r2 / 8.0).exp();
            // A little texture so that the rows have a noise level.
            let tex = 0.01 * (((x * 7 + y * 13) % 11) as f32 / 11.0);
            img.set(x, y, 0.05 + tex + s + lamp);
            truth.set(x, y, if s > 0.25 { 1.0 } else { 0.0 });
        }
    }
    (img, truth)
}

#[test]
fn an_image_streak_is_masked_and_scored() {
    let t = TestDir::new();
    let (img, truth) = streak_image();
    img.save_png(&t.join("road.png")).unwrap();
    truth.save_png(&t.join("truth.png")).unwrap();
    let run = t.streaks(&[
        "detect",
        "road.png",
        "--detector",
        "hand",
        "--truth",
        "truth.png",
        "--horizon",
        "60",
        "-o",
        "mask.png",
    ]);
    run.assert_success();
    let score: Value = serde_json::from_slice(&run.output.stdout).unwrap();
    let (p, r) = (
        score["precision"].as_f64().unwrap(),
        score["recall"].as_f64().unwrap(),
    );
    assert!(p > 0.9 && r > 0.8, "{score}");
    // The mask is the one scored, and the lamp is not in it.
    assert_eq!(
        score["detected"].as_u64().unwrap(),
        count(&t.join("mask.png"), None)
    );
    let mask = GrayImage::load(&t.join("mask.png")).unwrap();
    assert!((0..60).all(|y| (0..160).all(|x| mask.get(x, y) == 0.0)));
    assert!(run.stderr().contains("1 streaks"), "{}", run.stderr());
}

#[test]
fn a_dataset_is_scored_per_sample_and_pooled_against_its_masks() {
    let t = TestDir::new();
    t.streaks(&[
        "dataset", "generate", "-o", "ds", "--count", "3", "--width", "96", "--height", "64",
        "--spp", "4",
    ])
    .assert_success();
    t.streaks(&["detect", "ds", "-o", "scores.json"])
        .assert_success();
    let s: Value =
        serde_json::from_str(&std::fs::read_to_string(t.join("scores.json")).unwrap()).unwrap();
    let samples = s["samples"].as_array().unwrap();
    assert_eq!(samples.len(), 3);
    let (mut tp, mut det, mut truth) = (0, 0, 0);
    for sample in samples {
        let dir = t.join("ds/samples").join(sample["id"].as_str().unwrap());
        let (all, road) = (&sample["all"], &sample["road"]);
        // The truths are the dataset's own masks: all of streaks0.png, and its part on road0.png.
        assert_eq!(
            all["truth"].as_u64().unwrap(),
            count(&dir.join("streaks0.png"), None)
        );
        assert_eq!(
            road["truth"].as_u64().unwrap(),
            count(&dir.join("streaks0.png"), Some(&dir.join("road0.png")))
        );
        assert!(road["true_positives"].as_u64() <= road["detected"].as_u64());
        assert!(road["true_positives"].as_u64() <= road["truth"].as_u64());
        tp += road["true_positives"].as_u64().unwrap();
        det += road["detected"].as_u64().unwrap();
        truth += road["truth"].as_u64().unwrap();
    }
    // Pooled: the counts summed, precision and recall from them.
    let pooled = &s["road"];
    assert_eq!(pooled["true_positives"].as_u64().unwrap(), tp);
    assert_eq!(pooled["detected"].as_u64().unwrap(), det);
    assert_eq!(pooled["truth"].as_u64().unwrap(), truth);
    if det > 0 {
        let p = pooled["precision"].as_f64().unwrap();
        assert!((p - tp as f64 / det as f64).abs() < 1e-12);
    }
    // A split keeps only its samples.
    let split = std::fs::read_to_string(t.join("ds/splits/train.txt")).unwrap();
    let n = split.split_whitespace().count();
    t.streaks(&["detect", "ds", "--split", "train", "-o", "train.json"])
        .assert_success();
    let s: Value =
        serde_json::from_str(&std::fs::read_to_string(t.join("train.json")).unwrap()).unwrap();
    assert_eq!(s["samples"].as_array().unwrap().len(), n);
}

#[test]
fn bad_detect_input_fails_without_writing() {
    let t = TestDir::new();
    t.streaks(&["detect", "missing.png"])
        .assert_failure_mentioning("missing.png");
    let (img, _) = streak_image();
    img.save_png(&t.join("road.png")).unwrap();
    GrayImage::new(10, 10, 0.0)
        .unwrap()
        .save_png(&t.join("small.png"))
        .unwrap();
    t.streaks(&[
        "detect",
        "road.png",
        "--truth",
        "small.png",
        "-o",
        "mask.png",
    ])
    .assert_failure_mentioning("small.png is 10x10");
    assert!(!t.join("mask.png").exists());
    std::fs::create_dir(t.join("empty")).unwrap();
    t.streaks(&["detect", "empty"])
        .assert_failure_mentioning("without dataset.json");
    t.streaks(&["detect", "road.png", "--split", "test"])
        .assert_failure_mentioning("--split and --image apply to a dataset");
    t.streaks(&[
        "detect",
        "road.png",
        "--detector",
        "hand",
        "--row-fraction",
        "2",
    ])
    .assert_failure_mentioning("row_fraction");
    t.streaks(&[
        "detect",
        "road.png",
        "--detector",
        "learned",
        "--row-fraction",
        "0.3",
    ])
    .assert_failure_mentioning("need --detector hand");
    std::fs::write(
        t.join("model.json"),
        "{\"format\": \"streaks-classifier/1\"}",
    )
    .unwrap();
    t.streaks(&[
        "detect",
        "road.png",
        "--model",
        "model.json",
        "-o",
        "mask.png",
    ])
    .assert_failure_mentioning("model.json is not a usable streak classifier");
    t.streaks(&["detect", "road.png", "--threshold", "1.5", "-o", "mask.png"])
        .assert_failure_mentioning("not a probability");
    assert!(!t.join("mask.png").exists());
    t.streaks(&["train-detector", "empty", "-o", "m.json"])
        .assert_failure_mentioning("not a dataset folder");
    assert!(!t.join("m.json").exists());
}

/// `train-detector` writes a classifier that `detect` reads and applies, and its trees learn the
/// masks of the streets they were trained on.
///
/// Six 96x64 samples at 4 spp are enough for the trees but not for the validation step: it has
/// one sample of another street, whose few dozen streak pixels (1-2 px wide at this size) give
/// an operating point that holds nowhere else, often a smoothing that erases the streaks
/// altogether (seeds 0-3: road F1 0.0-0.31 on the training split at the chosen point, 0.85-0.94
/// at threshold 0.5 without smoothing). So the operating point is only checked for its
/// plumbing, and the trees are scored on their training split at threshold 0.5, unsmoothed.
#[test]
fn a_classifier_trained_on_a_dataset_is_used_by_detect() {
    let t = TestDir::new();
    // Train on the split with most samples, choose the threshold on the one with fewest.
    let splits = t.tiny_dataset(None);
    let (train, val) = (splits[0], splits[splits.len() - 1]);
    assert_ne!(train, val, "{splits:?}");
    let run = t.streaks(&[
        "train-detector",
        "ds",
        "-o",
        "model.json",
        "--train-split",
        train,
        "--val-split",
        val,
        "--rounds",
        "20",
        "--min-leaf",
        "20",
        "--precision",
        "0.5",
    ]);
    run.assert_success();
    assert!(
        run.stderr().contains("kept smoothing radius"),
        "{}",
        run.stderr()
    );
    let model: Value =
        serde_json::from_str(&std::fs::read_to_string(t.join("model.json")).unwrap()).unwrap();
    assert_eq!(model["format"], "streaks-classifier/1");
    assert_eq!(model["model"]["trees"].as_array().unwrap().len(), 20);
    assert_eq!(model["provenance"]["train_split"], train);
    assert!(
        model["smooth"].as_u64().unwrap() <= 2,
        "{}",
        model["smooth"]
    );
    // The trees score their own training split well: they have learned the masks. Unsmoothed,
    // at an overridden threshold: the operating point of one tiny validation sample is noise.
    let mut unsmoothed = model.clone();
    unsmoothed["smooth"] = 0.into();
    std::fs::write(t.join("model0.json"), unsmoothed.to_string()).unwrap();
    t.streaks(&[
        "detect",
        "ds",
        "--model",
        "model0.json",
        "--threshold",
        "0.5",
        "--split",
        train,
        "-o",
        "s.json",
    ])
    .assert_success();
    let s: Value =
        serde_json::from_str(&std::fs::read_to_string(t.join("s.json")).unwrap()).unwrap();
    assert_eq!(s["image"], "im0.exr");
    let road = &s["road"];
    assert!(road["f1"].as_f64().unwrap() > 0.5, "{s}");
    // The same on one image, with the sample's horizon: the mask is written and non-empty.
    let id = s["samples"][0]["id"].as_str().unwrap();
    let horizon = s["samples"][0]["horizon"].as_f64().unwrap().to_string();
    let exr = format!("ds/samples/{id}/im0.exr");
    t.streaks(&[
        "detect",
        &exr,
        "--model",
        "model0.json",
        "--threshold",
        "0.5",
        "--horizon",
        &horizon,
        "-o",
        "one.png",
    ])
    .assert_success();
    let n = count(&t.join("one.png"), None);
    assert_eq!(n, s["samples"][0]["all"]["detected"].as_u64().unwrap());
}
