//! Gradient-boosted decision trees for binary classification (logistic loss), trained on
//! histograms: the learned half of streak detection ([`crate::streak_classifier`]).
//!
//! Training follows LightGBM and scikit-learn's `HistGradientBoostingClassifier`:
//!
//! 1. Each feature is cut into at most [`TrainParams::bins`] bins at its quantiles (taken over
//!    the training rows). A split is a bin edge, stored as the raw feature value, so inference
//!    reads raw features.
//! 2. The model starts at the log-odds of the positive share. Each round fits one tree to the
//!    logistic loss's gradient `g = p - y` and hessian `h = p (1 - p)`: the tree grows best
//!    leaf first (the leaf whose best split gains most), up to [`TrainParams::max_leaves`]
//!    leaves, with splits gaining `G_L²/(H_L+λ) + G_R²/(H_R+λ) - G²/(H+λ)` and leaves worth
//!    `-G/(H+λ)` times the learning rate; a leaf keeps at least
//!    [`TrainParams::min_leaf`] rows.
//!
//! Training is deterministic: no sampling; ties go to the lower feature and bin. Histograms
//! are built in parallel over features (rayon), each in one fixed order, so the model does
//! not depend on the number of threads.
//!
//! Inference ([`Model::score`]) walks each tree from its root: `x[feature] <= threshold` goes
//! left. It allocates nothing. The model is plain data (serde) and is saved as JSON.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Errors of training or loading a model.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum GbdtError {
    /// The training rows are unusable.
    #[error("cannot train: {0}")]
    Data(String),
    /// A training parameter is out of range.
    #[error("invalid training parameter {name}: {reason}")]
    Param {
        /// The parameter.
        name: &'static str,
        /// Why.
        reason: &'static str,
    },
    /// A model's trees are malformed (a child index out of range, a feature the model does
    /// not have, a cycle).
    #[error("malformed model: {0}")]
    Malformed(String),
}

/// Training parameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrainParams {
    /// Boosting rounds (trees).
    pub rounds: usize,
    /// Shrinkage of each tree's leaves.
    pub learning_rate: f32,
    /// Most leaves per tree.
    pub max_leaves: usize,
    /// Fewest training rows in a leaf.
    pub min_leaf: usize,
    /// L2 regularisation `λ` of the leaf values.
    pub l2: f32,
    /// Most bins per feature (2..=256).
    pub bins: usize,
}

impl Default for TrainParams {
    /// scikit-learn's `HistGradientBoostingClassifier` defaults, with 200 rounds.
    fn default() -> Self {
        Self {
            rounds: 200,
            learning_rate: 0.1,
            max_leaves: 31,
            min_leaf: 20,
            l2: 0.0,
            bins: 255,
        }
    }
}

impl TrainParams {
    /// Checks the parameters.
    pub fn validate(&self) -> Result<(), GbdtError> {
        let bad = |name, reason| Err(GbdtError::Param { name, reason });
        if self.rounds == 0 {
            return bad("rounds", "must be at least 1");
        }
        if !(self.learning_rate > 0.0 && self.learning_rate <= 1.0) {
            return bad("learning_rate", "must be in (0, 1]");
        }
        if self.max_leaves < 2 {
            return bad("max_leaves", "must be at least 2");
        }
        if self.min_leaf == 0 {
            return bad("min_leaf", "must be at least 1");
        }
        if !(self.l2 >= 0.0 && self.l2.is_finite()) {
            return bad("l2", "must be finite and >= 0");
        }
        if !(2..=256).contains(&self.bins) {
            return bad("bins", "must be in 2..=256");
        }
        Ok(())
    }
}

/// One node of a tree: a split, or a leaf (`left == 0`, see [`Node::is_leaf`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Node {
    /// The feature a split tests.
    pub feature: u16,
    /// A split sends `x[feature] <= threshold` to `left`, the rest to `right`; a leaf's
    /// value (its contribution to the log-odds).
    pub value: f32,
    /// Index of the left child in the tree's nodes (0 for a leaf: the root is nobody's child).
    pub left: u32,
    /// Index of the right child (0 for a leaf).
    pub right: u32,
}

impl Node {
    /// Whether the node is a leaf.
    pub fn is_leaf(&self) -> bool {
        self.left == 0
    }
}

/// A trained classifier: the sum of its trees' leaves plus `base` is the log-odds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Model {
    /// Number of features a row has.
    pub features: usize,
    /// Log-odds before any tree.
    pub base: f32,
    /// The trees, each a list of nodes with its root first.
    pub trees: Vec<Vec<Node>>,
}

impl Model {
    /// The log-odds of the positive class for `row` (at least [`Model::features`] values).
    pub fn score(&self, row: &[f32]) -> f32 {
        let mut s = self.base;
        for tree in &self.trees {
            s += leaf(tree, row);
        }
        s
    }

    /// The probability of the positive class for `row`.
    pub fn probability(&self, row: &[f32]) -> f32 {
        sigmoid(self.score(row))
    }

    /// [`Model::probability`] of each of the rows of `rows` (row-major, `stride` values a
    /// row, at least [`Model::features`]) into `out` (one per row), bit for bit the same.
    /// Tree by tree over the whole block rather than row by row: one tree's nodes stay in
    /// the cache for every row, where a row's walk through hundreds of trees would evict them.
    pub fn probabilities(&self, rows: &[f32], stride: usize, out: &mut [f32]) {
        out.fill(self.base);
        for tree in &self.trees {
            for (s, row) in out.iter_mut().zip(rows.chunks_exact(stride)) {
                *s += leaf(tree, row);
            }
        }
        for s in out.iter_mut() {
            *s = sigmoid(*s);
        }
    }

    /// [`Model::probability`] of `n` items (pixels, say) whose rows of `width` features
    /// `row_of(i, row)` writes, for the items `at` accepts, `otherwise` for the others (an
    /// item that needs no answer is not asked: the trees are its cost). In parallel over
    /// blocks of items, each scored tree by tree ([`Model::probabilities`]) from one buffer
    /// per worker; bit for bit [`Model::probability`] of each row.
    pub fn probabilities_of(
        &self,
        n: usize,
        width: usize,
        row_of: impl Fn(usize, &mut [f32]) + Sync,
        at: impl Fn(usize) -> bool + Sync,
        otherwise: f32,
    ) -> Vec<f32> {
        const BLOCK: usize = 256;
        let mut data = vec![otherwise; n];
        data.par_chunks_mut(BLOCK).enumerate().for_each_init(
            || {
                (
                    Vec::with_capacity(BLOCK * width),
                    Vec::with_capacity(BLOCK),
                    Vec::with_capacity(BLOCK),
                    vec![0f32; width],
                )
            },
            |(rows, asked, scores, row): &mut (Vec<f32>, Vec<usize>, Vec<f32>, Vec<f32>),
             (b, out)| {
                rows.clear();
                asked.clear();
                for k in 0..out.len() {
                    let i = b * BLOCK + k;
                    if at(i) {
                        row_of(i, row);
                        rows.extend_from_slice(row);
                        asked.push(k);
                    }
                }
                scores.resize(asked.len(), 0.0);
                self.probabilities(rows, width, scores);
                for (&k, &p) in asked.iter().zip(scores.iter()) {
                    out[k] = p;
                }
            },
        );
        data
    }

    /// Checks that every tree is well formed: children in range and after their parent (so
    /// [`Model::score`] terminates), features below [`Model::features`], finite values.
    pub fn validate(&self) -> Result<(), GbdtError> {
        if !self.base.is_finite() {
            return Err(GbdtError::Malformed("the base score is not finite".into()));
        }
        for (t, tree) in self.trees.iter().enumerate() {
            if tree.is_empty() {
                return Err(GbdtError::Malformed(format!("tree {t} has no nodes")));
            }
            for (i, n) in tree.iter().enumerate() {
                let bad =
                    |why: &str| Err(GbdtError::Malformed(format!("tree {t} node {i}: {why}")));
                if !n.value.is_finite() {
                    return bad("value is not finite");
                }
                if n.is_leaf() {
                    if n.right != 0 {
                        return bad("a leaf with a right child");
                    }
                    continue;
                }
                if n.feature as usize >= self.features {
                    return bad("feature out of range");
                }
                for c in [n.left, n.right] {
                    if c as usize <= i || c as usize >= tree.len() {
                        return bad("child index out of range");
                    }
                }
            }
        }
        Ok(())
    }
}

/// The value of the leaf `row` reaches in `tree` (its root first).
#[inline]
fn leaf(tree: &[Node], row: &[f32]) -> f32 {
    let mut n = &tree[0];
    while !n.is_leaf() {
        let i = if row[n.feature as usize] <= n.value {
            n.left
        } else {
            n.right
        };
        n = &tree[i as usize];
    }
    n.value
}

/// The logistic function.
pub fn sigmoid(x: f32) -> f32 {
    1.0 / (1.0 + (-x).exp())
}

/// Training rows: `features` values per row, row-major, and a label per row.
#[derive(Clone, Debug, Default)]
pub struct Dataset {
    /// Values per row.
    pub features: usize,
    /// `rows * features` values.
    pub values: Vec<f32>,
    /// One label per row.
    pub labels: Vec<bool>,
}

impl Dataset {
    /// An empty dataset of rows with `features` values.
    pub fn new(features: usize) -> Self {
        Self {
            features,
            ..Self::default()
        }
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.labels.len()
    }

    /// Appends a row.
    pub fn push(&mut self, row: &[f32], label: bool) {
        debug_assert_eq!(row.len(), self.features);
        self.values.extend_from_slice(row);
        self.labels.push(label);
    }

    /// Appends the rows of `other` (same number of features).
    pub fn extend(&mut self, other: &Dataset) {
        debug_assert_eq!(other.features, self.features);
        self.values.extend_from_slice(&other.values);
        self.labels.extend_from_slice(&other.labels);
    }
}

/// Per-feature bin edges: bin `b` holds values in `(edge[b-1], edge[b]]`.
fn bin_edges(data: &Dataset, bins: usize) -> Vec<Vec<f32>> {
    let n = data.rows();
    (0..data.features)
        .into_par_iter()
        .map(|f| {
            let mut col: Vec<f32> = (0..n).map(|r| data.values[r * data.features + f]).collect();
            col.sort_unstable_by(f32::total_cmp);
            let mut edges = Vec::with_capacity(bins);
            for b in 1..bins {
                let v = col[(b * n / bins).min(n - 1)];
                if edges.last().is_none_or(|&e| v > e) && v < col[n - 1] {
                    edges.push(v);
                }
            }
            edges
        })
        .collect()
}

/// One feature's histogram: gradient and hessian sums and row counts per bin.
#[derive(Clone, Default)]
struct Hist {
    g: Vec<f64>,
    h: Vec<f64>,
    n: Vec<u32>,
}

impl Hist {
    /// `self - other`, bin by bin: the histogram of a leaf's larger child from its parent's
    /// and the smaller child's (LightGBM's subtraction trick).
    fn minus(&self, other: &Hist) -> Hist {
        Hist {
            g: self.g.iter().zip(&other.g).map(|(a, b)| a - b).collect(),
            h: self.h.iter().zip(&other.h).map(|(a, b)| a - b).collect(),
            n: self.n.iter().zip(&other.n).map(|(a, b)| a - b).collect(),
        }
    }
}

/// The best split of a leaf.
#[derive(Clone, Copy, Debug)]
struct Split {
    gain: f64,
    feature: usize,
    /// Rows with bin <= `bin` go left.
    bin: u8,
}

/// A leaf of the tree being grown: its node, rows (ascending), sums, histograms and best
/// split.
struct Leaf {
    node: usize,
    rows: Vec<u32>,
    g: f64,
    h: f64,
    hists: Vec<Hist>,
    split: Option<Split>,
}

/// Grows the trees of one boosting round.
struct Grower<'a> {
    /// Bin of each value, feature-major: `binned[f * rows + r]`.
    binned: &'a [u8],
    rows: usize,
    nbins: &'a [usize],
    grad: &'a [f32],
    hess: &'a [f32],
    params: &'a TrainParams,
}

impl Grower<'_> {
    fn bin(&self, feature: usize, row: u32) -> u8 {
        self.binned[feature * self.rows + row as usize]
    }

    fn histograms(&self, rows: &[u32]) -> Vec<Hist> {
        (0..self.nbins.len())
            .into_par_iter()
            .map(|f| {
                let nb = self.nbins[f];
                let col = &self.binned[f * self.rows..(f + 1) * self.rows];
                let mut hist = Hist {
                    g: vec![0.0; nb],
                    h: vec![0.0; nb],
                    n: vec![0; nb],
                };
                for &r in rows {
                    let r = r as usize;
                    let b = col[r] as usize;
                    hist.g[b] += self.grad[r] as f64;
                    hist.h[b] += self.hess[r] as f64;
                    hist.n[b] += 1;
                }
                hist
            })
            .collect()
    }

    fn best_split(&self, hists: &[Hist], n: u32, g: f64, h: f64) -> Option<Split> {
        let min_leaf = self.params.min_leaf as u32;
        if n < 2 * min_leaf {
            return None;
        }
        let l2 = self.params.l2 as f64;
        let parent = g * g / (h + l2);
        let mut best: Option<Split> = None;
        for (f, hist) in hists.iter().enumerate() {
            let (mut gl, mut hl, mut nl) = (0.0, 0.0, 0u32);
            for b in 0..self.nbins[f].saturating_sub(1) {
                gl += hist.g[b];
                hl += hist.h[b];
                nl += hist.n[b];
                if nl < min_leaf || n - nl < min_leaf {
                    continue;
                }
                let (gr, hr) = (g - gl, h - hl);
                if hl <= 1e-12 || hr <= 1e-12 {
                    continue;
                }
                let gain = gl * gl / (hl + l2) + gr * gr / (hr + l2) - parent;
                if gain > 1e-9 && best.is_none_or(|s| gain > s.gain) {
                    best = Some(Split {
                        gain,
                        feature: f,
                        bin: b as u8,
                    });
                }
            }
        }
        best
    }

    /// A leaf of `rows` whose histograms are known.
    fn leaf(&self, node: usize, rows: Vec<u32>, hists: Vec<Hist>) -> Leaf {
        // Every row falls in exactly one bin of feature 0: its sums are the leaf's.
        let g = hists[0].g.iter().sum();
        let h = hists[0].h.iter().sum();
        let split = self.best_split(&hists, rows.len() as u32, g, h);
        Leaf {
            node,
            rows,
            g,
            h,
            hists,
            split,
        }
    }

    /// Grows one tree on all rows; returns its nodes (leaf values already shrunk).
    fn grow(&self, edges: &[Vec<f32>], all_rows: &[u32]) -> Vec<Node> {
        let leaf_node = Node {
            feature: 0,
            value: 0.0,
            left: 0,
            right: 0,
        };
        let mut nodes = vec![leaf_node];
        let mut leaves = vec![self.leaf(0, all_rows.to_vec(), self.histograms(all_rows))];
        while leaves.len() < self.params.max_leaves {
            // The leaf whose split gains most (the first on ties).
            let mut chosen: Option<(usize, f64)> = None;
            for (i, l) in leaves.iter().enumerate() {
                if let Some(s) = l.split {
                    if chosen.is_none_or(|(_, g)| s.gain > g) {
                        chosen = Some((i, s.gain));
                    }
                }
            }
            let Some((i, _)) = chosen else { break };
            let leaf = leaves.swap_remove(i);
            let s = leaf.split.expect("chosen for its split");
            let (left, right): (Vec<u32>, Vec<u32>) = leaf
                .rows
                .iter()
                .partition(|&&r| self.bin(s.feature, r) <= s.bin);
            let (li, ri) = (nodes.len(), nodes.len() + 1);
            nodes[leaf.node] = Node {
                feature: s.feature as u16,
                value: edges[s.feature][s.bin as usize],
                left: li as u32,
                right: ri as u32,
            };
            nodes.extend([leaf_node; 2]);
            let left_smaller = left.len() <= right.len();
            let small_h = self.histograms(if left_smaller { &left } else { &right });
            let large_h: Vec<Hist> = leaf
                .hists
                .iter()
                .zip(&small_h)
                .map(|(p, c)| p.minus(c))
                .collect();
            let (lh, rh) = if left_smaller {
                (small_h, large_h)
            } else {
                (large_h, small_h)
            };
            leaves.push(self.leaf(li, left, lh));
            leaves.push(self.leaf(ri, right, rh));
        }
        let l2 = self.params.l2 as f64;
        for l in &leaves {
            nodes[l.node].value = (-l.g / (l.h + l2)) as f32 * self.params.learning_rate;
        }
        nodes
    }
}

/// Trains a classifier on `data`. `progress` is called after each round with the round's
/// number (1-based) and the training log-loss.
pub fn train(
    data: &Dataset,
    params: &TrainParams,
    mut progress: impl FnMut(usize, f64),
) -> Result<Model, GbdtError> {
    params.validate()?;
    let n = data.rows();
    if data.features == 0 || data.features > u16::MAX as usize {
        return Err(GbdtError::Data(format!(
            "rows must have 1..={} features, not {}",
            u16::MAX,
            data.features
        )));
    }
    if data.values.len() != n * data.features {
        return Err(GbdtError::Data(
            "values and labels disagree in number".into(),
        ));
    }
    if n > u32::MAX as usize {
        return Err(GbdtError::Data(format!("{n} rows are too many")));
    }
    if let Some(i) = data.values.iter().position(|v| !v.is_finite()) {
        return Err(GbdtError::Data(format!(
            "row {} feature {} is not finite",
            i / data.features,
            i % data.features
        )));
    }
    let positives = data.labels.iter().filter(|&&y| y).count();
    if positives == 0 || positives == n {
        return Err(GbdtError::Data(format!(
            "both classes are needed; {positives} of {n} rows are positive"
        )));
    }
    let edges = bin_edges(data, params.bins);
    // Feature-major bins: a histogram reads one contiguous column.
    let binned: Vec<u8> = (0..data.features)
        .into_par_iter()
        .flat_map_iter(|f| {
            let e = &edges[f];
            (0..n)
                .map(move |r| e.partition_point(|&x| x < data.values[r * data.features + f]) as u8)
        })
        .collect();
    let p0 = positives as f64 / n as f64;
    let base = (p0 / (1.0 - p0)).ln() as f32;
    let mut scores = vec![base; n];
    let (mut grad, mut hess) = (vec![0f32; n], vec![0f32; n]);
    let all_rows: Vec<u32> = (0..n as u32).collect();
    let nbins: Vec<usize> = edges.iter().map(|e| e.len() + 1).collect();
    let mut trees = Vec::with_capacity(params.rounds);
    for round in 1..=params.rounds {
        let mut loss = 0.0;
        for i in 0..n {
            let p = sigmoid(scores[i]).clamp(1e-7, 1.0 - 1e-7);
            let y = data.labels[i];
            grad[i] = p - y as u8 as f32;
            hess[i] = p * (1.0 - p);
            loss -= if y { p.ln() } else { (1.0 - p).ln() } as f64;
        }
        let grower = Grower {
            binned: &binned,
            rows: n,
            nbins: &nbins,
            grad: &grad,
            hess: &hess,
            params,
        };
        let tree = grower.grow(&edges, &all_rows);
        let model_tree = Model {
            features: data.features,
            base: 0.0,
            trees: vec![tree],
        };
        scores
            .par_iter_mut()
            .zip(data.values.par_chunks(data.features))
            .for_each(|(s, row)| *s += model_tree.score(row));
        trees.push(model_tree.trees.into_iter().next().expect("one tree"));
        progress(round, loss / n as f64);
    }
    let model = Model {
        features: data.features,
        base,
        trees,
    };
    model.validate()?;
    Ok(model)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rows on a grid in [0, 1]²; `label` decides each.
    fn grid(n: usize, label: impl Fn(f32, f32) -> bool) -> Dataset {
        let mut d = Dataset::new(2);
        for i in 0..n {
            for j in 0..n {
                let (x, y) = ((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                d.push(&[x, y], label(x, y));
            }
        }
        d
    }

    fn accuracy(m: &Model, d: &Dataset) -> f64 {
        let right = (0..d.rows())
            .filter(|&r| (m.probability(&d.values[r * 2..r * 2 + 2]) > 0.5) == d.labels[r])
            .count();
        right as f64 / d.rows() as f64
    }

    #[test]
    fn learns_a_disc_and_generalises_to_a_finer_grid() {
        let disc = |x: f32, y: f32| (x - 0.4).powi(2) + (y - 0.6).powi(2) < 0.09;
        let params = TrainParams {
            rounds: 60,
            ..TrainParams::default()
        };
        let mut losses = vec![];
        let m = train(&grid(60, disc), &params, |_, l| losses.push(l)).unwrap();
        assert_eq!(m.trees.len(), 60);
        // The loss falls round after round (boosting with exact Newton steps on a fixed set).
        assert!(losses.windows(2).all(|w| w[1] <= w[0] + 1e-9), "{losses:?}");
        assert!(
            losses[59] < 0.25 * losses[0],
            "{} -> {}",
            losses[0],
            losses[59]
        );
        let a = accuracy(&m, &grid(97, disc));
        assert!(a > 0.97, "held-out accuracy {a}");
    }

    #[test]
    fn a_block_scored_tree_by_tree_is_the_rows_scored_one_by_one_bit_for_bit() {
        let disc = |x: f32, y: f32| (x - 0.4).powi(2) + (y - 0.6).powi(2) < 0.09;
        let params = TrainParams {
            rounds: 30,
            ..TrainParams::default()
        };
        let m = train(&grid(40, disc), &params, |_, _| {}).unwrap();
        let test = grid(23, disc);
        let mut out = vec![0.0; test.rows()];
        m.probabilities(&test.values, test.features, &mut out);
        for (k, row) in test.values.chunks_exact(test.features).enumerate() {
            assert_eq!(out[k].to_bits(), m.probability(row).to_bits(), "row {k}");
        }
        m.probabilities(&[], test.features, &mut []);
        // Over blocks in parallel, with items left out: the same bits where asked, the
        // stand-in elsewhere (529 items: two full blocks and a part).
        let f = test.features;
        let all = m.probabilities_of(
            test.rows(),
            f,
            |i, row| row.copy_from_slice(&test.values[i * f..(i + 1) * f]),
            |i| i % 3 != 0,
            -1.0,
        );
        for (k, p) in all.iter().enumerate() {
            let want = if k % 3 != 0 { out[k] } else { -1.0 };
            assert_eq!(p.to_bits(), want.to_bits(), "item {k}");
        }
    }

    #[test]
    fn the_base_is_the_log_odds_and_a_constant_feature_is_never_split() {
        // Labels depend on x only; y is constant.
        let mut d = Dataset::new(2);
        for i in 0..400 {
            d.push(&[i as f32, 7.0], i % 4 == 0 || i > 300);
        }
        let m = train(
            &d,
            &TrainParams {
                rounds: 40,
                ..TrainParams::default()
            },
            |_, _| {},
        )
        .unwrap();
        let p0 = d.labels.iter().filter(|&&y| y).count() as f32 / 400.0;
        assert!((m.base - (p0 / (1.0 - p0)).ln()).abs() < 1e-6);
        for tree in &m.trees {
            assert!(tree.iter().all(|n| n.is_leaf() || n.feature == 0));
        }
        // The right end (all positive) is learned.
        assert!(m.probability(&[350.0, 7.0]) > 0.9);
        assert!(m.probability(&[150.0, 7.0]) < 0.5);
    }

    #[test]
    fn training_is_deterministic_across_thread_counts() {
        let d = grid(40, |x, y| x * 3.0 + y.sin() > 1.7);
        let p = TrainParams {
            rounds: 10,
            ..TrainParams::default()
        };
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| train(&d, &p, |_, _| {}).unwrap())
        };
        assert_eq!(run(1), run(3));
    }

    #[test]
    fn models_round_trip_through_json_and_bad_ones_are_refused() {
        let d = grid(20, |x, _| x > 0.5);
        let m = train(
            &d,
            &TrainParams {
                rounds: 3,
                ..TrainParams::default()
            },
            |_, _| {},
        )
        .unwrap();
        let back: Model = serde_json::from_str(&serde_json::to_string(&m).unwrap()).unwrap();
        assert_eq!(back, m);
        let mut bad = m.clone();
        bad.trees[0][0].left = 0;
        bad.trees[0][0].right = 99;
        assert!(matches!(bad.validate(), Err(GbdtError::Malformed(_))));
        let mut bad = m;
        bad.trees[1][0].feature = 5;
        assert!(matches!(bad.validate(), Err(GbdtError::Malformed(_))));
    }

    #[test]
    fn bad_training_input_is_an_error() {
        let p = TrainParams::default();
        let mut one_class = Dataset::new(1);
        one_class.push(&[1.0], true);
        one_class.push(&[2.0], true);
        assert!(matches!(
            train(&one_class, &p, |_, _| {}),
            Err(GbdtError::Data(_))
        ));
        let mut nan = Dataset::new(1);
        nan.push(&[f32::NAN], true);
        nan.push(&[2.0], false);
        assert!(matches!(
            train(&nan, &p, |_, _| {}),
            Err(GbdtError::Data(_))
        ));
        let bad = TrainParams { max_leaves: 1, ..p };
        assert!(matches!(bad.validate(), Err(GbdtError::Param { .. })));
    }
}
