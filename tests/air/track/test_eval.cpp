// OTB one-pass metrics, the sequence reader, the attributes, the LOST-flag score and the k-fold protocol.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "air/track/eval/attributes.hpp"
#include "air/track/eval/folds.hpp"
#include "air/track/eval/grid.hpp"
#include "air/track/eval/lost.hpp"
#include "air/track/eval/metrics.hpp"
#include "air/track/eval/sequence.hpp"
#include "tests/support/test_support.hpp"

using namespace aerie::track::eval;

TEST(Metrics, IouAndCentreErrorByHand) {
  EXPECT_DOUBLE_EQ(iou({0, 0, 10, 10}, {5, 0, 10, 10}), 50.0 / 150.0);
  EXPECT_DOUBLE_EQ(iou({0, 0, 10, 10}, {20, 20, 5, 5}), 0.0);
  EXPECT_DOUBLE_EQ(iou({0, 0, 10, 10}, {0, 0, 10, 10}), 1.0);
  EXPECT_DOUBLE_EQ(centre_error({0, 0, 10, 10}, {3, 4, 10, 10}), 5.0);
}

TEST(Metrics, SuccessAucPrecisionAndMeanErrorByHand) {
  // four frames: IoU 1, 1/3 (shift 5 of 10), 0 (far), and an invalid ground truth (skipped)
  const std::vector<cv::Rect2d> gt = {{0, 0, 10, 10}, {0, 0, 10, 10}, {0, 0, 10, 10}, {0, 0, 0, 0}};
  const std::vector<cv::Rect2d> pr = {{0, 0, 10, 10}, {5, 0, 10, 10}, {100, 0, 10, 10}, {0, 0, 10, 10}};
  const Score s = score(pr, gt);
  EXPECT_EQ(s.frames, 3);
  ASSERT_EQ(s.success.size(), 21u);
  EXPECT_DOUBLE_EQ(s.success[0], 2.0 / 3);   // IoU > 0
  EXPECT_DOUBLE_EQ(s.success[6], 2.0 / 3);   // > 0.30: 1 and 0.333
  EXPECT_DOUBLE_EQ(s.success[7], 1.0 / 3);   // > 0.35
  EXPECT_DOUBLE_EQ(s.success[20], 0.0);      // > 1: never
  // AUC = mean over the 21 thresholds: 7 thresholds (0..0.30) at 2/3, 13 (0.35..0.95) at 1/3
  EXPECT_NEAR(s.auc, (7 * 2.0 / 3 + 13 * 1.0 / 3) / 21, 1e-12);
  EXPECT_DOUBLE_EQ(s.precision20, 2.0 / 3);  // errors 0, 5, 100
  EXPECT_DOUBLE_EQ(s.mean_centre_error, 35.0);
  EXPECT_THROW(score({{0, 0, 1, 1}}, gt), std::invalid_argument);
}

TEST(Sequence, BoxesRoundTripAndBadFilesNameTheLine) {
  const auto dir = aerie::test::scratch_dir("boxes");
  const std::vector<cv::Rect2d> boxes = {{1.5, 2, 30, 40.25}, {0, 0, 10, 10}};
  write_boxes(dir / "a.txt", boxes);
  EXPECT_EQ(read_boxes(dir / "a.txt"), boxes);
  std::ofstream(dir / "tabs.txt") << "1\t2\t3\t4\nNaN,NaN,NaN,NaN\n";
  const auto t = read_boxes(dir / "tabs.txt");
  ASSERT_EQ(t.size(), 2u);
  EXPECT_FALSE(is_valid_box(t[1]));
  std::ofstream(dir / "bad.txt") << "1,2,3,4\n1,2,x,4\n";
  try {
    read_boxes(dir / "bad.txt");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.txt:2"), std::string::npos) << e.what();
  }
}

TEST(Sequence, FindsOtbFoldersAndChecksCounts) {
  const auto dir = aerie::test::scratch_dir("data");
  std::filesystem::create_directories(dir / "A" / "img");
  std::filesystem::create_directories(dir / "notaseq");
  for (int i = 1; i <= 3; ++i) std::ofstream(dir / "A" / "img" / ("000" + std::to_string(i) + ".jpg")) << "x";
  std::ofstream(dir / "A" / "groundtruth.txt") << "1,2,3,4\n1,2,3,4\n";
  EXPECT_THROW(find_sequences(dir), std::runtime_error);  // 3 frames, 2 boxes
  std::ofstream(dir / "A" / "groundtruth.txt", std::ios::app) << "1,2,3,4\n";
  const auto seqs = find_sequences(dir);
  ASSERT_EQ(seqs.size(), 1u);
  EXPECT_EQ(seqs[0].name, "A");
  EXPECT_EQ(seqs[0].frames.back().filename(), "0003.jpg");
}

// TRE segments by hand: 10 frames, k = 3 -> starts floor(10 j / 3) = 3, 6 (0-based); frame 3 has no
// visible target, so that segment starts at frame 4 ("@5", 1-based). k larger than the frames
// gives each start once and never a segment of fewer than 2 frames.
TEST(Sequence, TemporalSegmentsByHand) {
  Sequence s{"S", "dir", {}, {}};
  for (int i = 0; i < 10; ++i) {
    s.frames.push_back("f" + std::to_string(i) + ".jpg");
    s.groundtruth.push_back(i == 3 ? cv::Rect2d(0, 0, NAN, NAN) : cv::Rect2d(i, 0, 5, 5));
  }
  const auto seg = temporal_segments(s, 3);
  ASSERT_EQ(seg.size(), 3u);
  EXPECT_EQ(seg[0].name, "S");
  EXPECT_EQ(seg[0].frames.size(), 10u);
  EXPECT_EQ(seg[1].name, "S@5");
  EXPECT_EQ(seg[1].frames.size(), 6u);
  EXPECT_EQ(seg[1].frames.front(), "f4.jpg");
  EXPECT_EQ(seg[1].groundtruth.front().x, 4);
  EXPECT_EQ(seg[2].name, "S@7");
  EXPECT_EQ(seg[2].groundtruth.size(), 4u);
  EXPECT_EQ(temporal_segments(s, 1).size(), 1u);
  const auto many = temporal_segments(s, 40);  // the sequence, then 1, 2, 4 (3 moved on), 5, 6, 7, 8; 9 leaves 1 frame
  ASSERT_EQ(many.size(), 8u);
  EXPECT_EQ(many.back().name, "S@9");
  EXPECT_EQ(many.back().frames.size(), 2u);
  EXPECT_EQ(base_name("S@9"), "S");
  EXPECT_EQ(base_name("S"), "S");
  EXPECT_THROW(temporal_segments(s, 0), std::invalid_argument);
}

TEST(Sequence, SharedGirlSequence) {
  AERIE_REQUIRE_DATA("tracking/Girl");
  const Sequence s = load_sequence(aerie::test::shared_data("tracking/Girl"));
  EXPECT_EQ(s.frames.size(), 500u);
  EXPECT_EQ(s.groundtruth[0], cv::Rect2d(57, 21, 31, 45));
}

namespace {
const cv::Rect2d kGt{0, 0, 10, 10};
const cv::Rect2d kFar{100, 100, 10, 10};  // IoU 0
const cv::Rect2d kThird{5, 0, 10, 10};    // IoU 1/3: neither lost nor clearly tracked
const cv::Rect2d kHalf{0, 0, 10, 5};      // IoU exactly 0.5: not > 0.5
const cv::Rect2d kAbsent{NAN, NAN, NAN, NAN};
}  // namespace

TEST(Lost, EpisodesWindowAndFalseAlarmsByHand) {
  // frame: 0 init (flag ignored) | 1 tracked, flagged = false alarm | 2-4 episode A (IoU 0, then two
  // absent frames), flagged on its 3rd frame | 5 IoU 1/3 ends A | 6-11 episode B, flagged only on its
  // 6th frame (outside the window) | 12 tracked | 13 IoU 0.5, flagged (not > 0.5: no alarm) |
  // 14 episode C, absent, 1 frame at the end, not flagged
  const std::vector<cv::Rect2d> gt = {kGt, kGt, kGt, kAbsent, kAbsent, kGt, kGt, kGt,
                                      kGt, kGt, kGt, kGt, kGt, kGt, kAbsent};
  const std::vector<cv::Rect2d> pr = {kGt, kGt, kFar, kFar, kGt, kThird, kFar, kFar,
                                      kFar, kFar, kFar, kFar, kGt, kHalf, kGt};
  const std::vector<bool> lost = {true, true, false, false, true, false, false, false,
                                  false, false, false, true, false, true, false};
  const LostScore s = lost_detection(lost, pr, gt);
  EXPECT_EQ(s.episodes, 3);
  EXPECT_EQ(s.flagged, 1);
  EXPECT_EQ(s.frames_iou_gt_05, 2);  // frames 1 and 12
  EXPECT_EQ(s.false_alarms, 1);      // frame 1
  EXPECT_DOUBLE_EQ(s.recall(), 1.0 / 3);
  EXPECT_DOUBLE_EQ(s.false_alarm_rate(), 0.5);
  // A window of 6 frames reaches episode B's flag.
  EXPECT_EQ(lost_detection(lost, pr, gt, 6).flagged, 2);
  EXPECT_EQ(lost_detection(lost, pr, gt, 2).flagged, 0);  // A's flag is on its 3rd frame
}

TEST(Lost, ShortEpisodesCountWithTheFramesTheyHaveAndPoolingAddsCounts) {
  // Two 1-frame episodes (frames 2 and 4), the second flagged; frames 1, 3 tracked.
  const std::vector<cv::Rect2d> gt(5, kGt);
  const std::vector<cv::Rect2d> pr = {kGt, kGt, kFar, kGt, kFar};
  const LostScore a = lost_detection({false, false, false, false, true}, pr, gt);
  EXPECT_EQ(a.episodes, 2);
  EXPECT_EQ(a.flagged, 1);
  EXPECT_EQ(a.frames_iou_gt_05, 2);
  EXPECT_EQ(a.false_alarms, 0);
  // Nothing lost and nothing tracked: both ratios undefined.
  const LostScore none = lost_detection({false, false}, {kGt, kThird}, {kGt, kGt});
  EXPECT_EQ(none.episodes, 0);
  EXPECT_TRUE(std::isnan(none.recall()));
  EXPECT_TRUE(std::isnan(none.false_alarm_rate()));
  // Pooled: counts added, the ratio of the sums (3/4), not the mean of the ratios (1/2 and 1).
  const LostScore b = lost_detection({false, true, true}, {kGt, kFar, kFar}, {kGt, kGt, kAbsent});
  EXPECT_EQ(b.episodes, 1);
  EXPECT_EQ(b.flagged, 1);
  LostScore pooled = a;
  pooled += b;
  pooled += none;
  EXPECT_EQ(pooled.episodes, 3);
  EXPECT_EQ(pooled.flagged, 2);
  EXPECT_DOUBLE_EQ(pooled.recall(), 2.0 / 3);
  EXPECT_EQ(pooled.frames_iou_gt_05, 2);
  EXPECT_THROW(lost_detection({false}, pr, gt), std::invalid_argument);
  EXPECT_THROW(lost_detection({false, false}, {kGt, kGt}, {kGt, kGt}, 0), std::invalid_argument);
}

TEST(Attributes, FlagsAndStatisticsFromHandMadeGroundTruth) {
  // Steps 0->1 (15 px) and 3->4 (21 px > 20) and 4->5 (0.71 px) are between annotated frames;
  // 1->3 (25 px) spans the absent frame 2 and does not count. Frame 5 has area 399 < 400.
  const std::vector<cv::Rect2d> gt = {{0, 0, 20, 20},  {15, 0, 20, 20}, kAbsent,
                                      {40, 0, 20, 20}, {61, 0, 20, 20}, {61, 0, 19, 21}};
  const Attributes a = attributes(gt);
  EXPECT_EQ(a.frames, 6);
  EXPECT_EQ(a.absent, 1);
  EXPECT_EQ(a.steps, 3);
  EXPECT_EQ(a.fast_steps, 1);
  EXPECT_DOUBLE_EQ(a.max_centre_shift, 21);
  EXPECT_DOUBLE_EQ(a.min_area, 399);
  EXPECT_EQ(a.small_frames, 1);
  EXPECT_TRUE(a.fast_motion);
  EXPECT_TRUE(a.low_resolution);
  EXPECT_TRUE(a.occlusion);  // the absent frame
  EXPECT_FALSE(a.scale_variation);
  EXPECT_TRUE(has_attribute(a, "FM") && has_attribute(a, "LR") && has_attribute(a, "OCC"));
  EXPECT_FALSE(has_attribute(a, "SV"));
  EXPECT_THROW(has_attribute(a, "IV"), std::invalid_argument);

  // Exactly 20 px, exactly 400 px and a scale of exactly 1/2 or 2 are inside OTB's thresholds.
  const std::vector<cv::Rect2d> edge = {{0, 0, 20, 20}, {20, 0, 20, 20}, {20, 0, 40, 40}, {20, 0, 10, 40}};
  const Attributes e = attributes(edge, {"SV", "IPR"});
  EXPECT_FALSE(e.fast_motion || e.low_resolution || e.occlusion || e.scale_variation);
  EXPECT_DOUBLE_EQ(e.max_scale, 2);
  // Beyond them: scale sqrt(41 * 40 / 400) > 2; the benchmark's OCC tag makes an occlusion sequence.
  const Attributes big = attributes({{0, 0, 20, 20}, {0, 0, 41, 40}}, {"OPR", "OCC"});
  EXPECT_TRUE(big.scale_variation);
  EXPECT_EQ(big.scale_frames, 1);
  EXPECT_TRUE(big.occlusion);
  EXPECT_FALSE(attributes({{0, 0, 20, 20}, {0, 0, 9, 9}}).occlusion);
  EXPECT_TRUE(attributes({{0, 0, 20, 20}, {0, 0, 9, 9}}).scale_variation);  // sqrt(81 / 400) = 0.45
  EXPECT_THROW(attributes({kAbsent, kGt}), std::invalid_argument);
}

TEST(Attributes, BenchmarkTagsFromSourceTxtAndWithoutIt) {
  const auto dir = aerie::test::scratch_dir("source");
  std::ofstream(dir / "tagged.txt") << "Sequence: X\nBenchmark attribute tags: OPR, SV, OCC, IPR  [OTB tags from "
                                       "MakeSequenceConfigVer10.m]\nGT-derived statistics: ...\n";
  std::ofstream(dir / "untagged.txt") << "Benchmark attribute tags: not copied (no verified attribute file)\n";
  EXPECT_EQ(benchmark_tags(dir / "tagged.txt"), (std::vector<std::string>{"OPR", "SV", "OCC", "IPR"}));
  EXPECT_TRUE(benchmark_tags(dir / "untagged.txt").empty());
  EXPECT_TRUE(benchmark_tags(dir / "missing.txt").empty());
  // A sequence folder without SOURCE.txt (a simulated one): OCC only from absent frames.
  Sequence seq{"sim", dir, {}, {kGt, kGt, kAbsent, kGt}};
  EXPECT_TRUE(attributes(seq).occlusion);
  EXPECT_FALSE(attributes(seq, 2).occlusion);  // the first 2 frames only
  std::ofstream(dir / "SOURCE.txt") << "Benchmark attribute tags: OCC  [test]\n";
  EXPECT_TRUE(attributes(seq, 2).occlusion);
}

TEST(Attributes, SharedSequencesMatchTheirSourceTxtStatistics) {
  AERIE_REQUIRE_DATA("tracking/uav123_10fps_car14");
  // SOURCE.txt: 25 absent frames, 9 of 33 steps > 20 px (0.273), 15 of 35 annotated frames < 400 px
  // (0.429), min area 221, scale (0.46, 1.04), max centre shift 43.5 px.
  const Attributes a = attributes(load_sequence(aerie::test::shared_data("tracking/uav123_10fps_car14")));
  EXPECT_EQ(a.absent, 25);
  EXPECT_EQ(a.steps, 33);
  EXPECT_EQ(a.fast_steps, 9);
  EXPECT_EQ(a.small_frames, 15);
  EXPECT_DOUBLE_EQ(a.min_area, 221);
  EXPECT_NEAR(a.min_scale, 0.46, 0.005);
  EXPECT_NEAR(a.max_centre_shift, 43.5, 0.05);
  EXPECT_TRUE(a.fast_motion && a.low_resolution && a.occlusion && a.scale_variation);
  EXPECT_TRUE(a.tags.empty());  // "not copied"
  AERIE_REQUIRE_DATA("tracking/Girl");
  const Attributes g = attributes(load_sequence(aerie::test::shared_data("tracking/Girl")));
  EXPECT_TRUE(g.occlusion);  // from the OTB tags only: Girl has no absent frame
  EXPECT_EQ(g.absent, 0);
  EXPECT_FALSE(g.fast_motion || g.low_resolution || g.scale_variation);  // 12 px, 620 px, (0.67, 1.28)
}

TEST(Folds, AssignmentBySortedNameModuloK) {
  const std::vector<std::string> names = {"b", "a", "d", "c", "e"};  // sorted: a b c d e
  EXPECT_EQ(assign_folds(names, 2), (std::vector<int>{1, 0, 1, 0, 0}));
  EXPECT_EQ(assign_folds(names, 5), (std::vector<int>{1, 0, 3, 2, 4}));  // leave one sequence out
  EXPECT_EQ(assign_folds({"Skiing", "uav123", "Girl"}, 3), (std::vector<int>{1, 2, 0}));  // byte order
  aerie::test::expect_refusals([&](const std::string& k) { assign_folds(names, std::stoi(k)); },
                               {{"1", "1 folds for 5 sequences"}, {"6", "need 2 <= folds <= sequences"},
                                {"0", "need 2 <= folds"}});
}

// A sequence's TRE segments share its fold; the count of folds is bounded by the sequences, not the segments.
TEST(Folds, SegmentsShareTheirSequencesFold) {
  const std::vector<std::string> names = {"b", "b@40", "a", "a@20", "c@7", "c", "a@60"};  // sequences: a b c
  EXPECT_EQ(assign_folds(names, 2), (std::vector<int>{1, 1, 0, 0, 0, 0, 0}));
  EXPECT_EQ(assign_folds(names, 3), (std::vector<int>{1, 1, 0, 0, 2, 2, 0}));
  EXPECT_THROW(assign_folds(names, 4), std::invalid_argument);  // 3 sequences
}

TEST(Folds, TunedOnAndHeldOutByHand) {
  // AUC (= P20 here) of 3 candidates on 4 sequences; CLE = 10 c + s. Folds: s0, s2 -> 0; s1, s3 -> 1.
  // Candidates 1 and 2 are each good on one fold only: tuning on one fold picks the one that fails
  // on the other, so held out they score 0.1 where the tuned-on figure says 0.85.
  const std::vector<double> auc[3] = {{0.5, 0.5, 0.5, 0.5}, {0.9, 0.1, 0.9, 0.1}, {0.1, 0.8, 0.1, 0.8}};
  std::vector<std::vector<Figures>> scores(3);
  for (int c = 0; c < 3; ++c)
    for (int s = 0; s < 4; ++s) scores[c].push_back({auc[c][s], auc[c][s], 10.0 * c + s});
  const std::vector<int> fold = {0, 1, 0, 1};
  const auto r = cross_validate(scores, fold);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].candidate, 2);  // tuned on s1, s3: 0.5, 0.1, 0.8
  EXPECT_EQ(r[0].tuned, (std::vector<size_t>{1, 3}));
  EXPECT_EQ(r[0].heldout, (std::vector<size_t>{0, 2}));
  EXPECT_DOUBLE_EQ(r[0].tuned_figures.auc, 0.8);
  EXPECT_DOUBLE_EQ(r[0].tuned_figures.mean_centre_error, 22);  // (21 + 23) / 2
  EXPECT_DOUBLE_EQ(r[0].heldout_figures.auc, 0.1);
  EXPECT_DOUBLE_EQ(r[0].heldout_figures.precision20, 0.1);
  EXPECT_DOUBLE_EQ(r[0].heldout_figures.mean_centre_error, 21);  // (20 + 22) / 2
  EXPECT_EQ(r[1].candidate, 1);  // tuned on s0, s2: 0.5, 0.9, 0.1
  EXPECT_DOUBLE_EQ(r[1].tuned_figures.auc, 0.9);
  EXPECT_DOUBLE_EQ(r[1].heldout_figures.mean_centre_error, 12);  // (11 + 13) / 2
  const HeldOutSummary h = summarise(r, scores);
  EXPECT_EQ(h.sequences, 4);
  EXPECT_DOUBLE_EQ(h.tuned.auc, 0.85);
  EXPECT_DOUBLE_EQ(h.heldout.auc, 0.1);
  EXPECT_DOUBLE_EQ(h.tuned.mean_centre_error, 16.5);
  EXPECT_DOUBLE_EQ(h.heldout.mean_centre_error, 16.5);  // (20 + 11 + 22 + 13) / 4

  // Ties go to the lower index; a single candidate is always chosen.
  std::vector<std::vector<Figures>> tie = {scores[0], scores[0]};
  for (const auto& f : cross_validate(tie, fold)) EXPECT_EQ(f.candidate, 0);
  EXPECT_EQ(cross_validate({scores[1]}, fold)[0].candidate, 0);
  EXPECT_THROW(cross_validate(scores, {0, 1, 0}), std::invalid_argument);    // 4 scores, 3 sequences
  EXPECT_THROW(cross_validate(scores, {0, 0, 0, 0}), std::invalid_argument);  // nothing to tune on
}

TEST(Folds, GridMergesCandidatesOverTheBaseSettings) {
  const auto base = aerie::util::Config::parse("dcf:\n  lambda: 0.02\n  learning_rate: 0.01\n", "track.yaml");
  const auto grid = aerie::util::Config::parse("dcf:\n  - {}\n  - {learning_rate: 0.05}\n", "grid.yaml");
  const auto c = load_grid(grid, base, {"dcf", "opencv-kcf"});
  ASSERT_EQ(c.size(), 2u);
  ASSERT_EQ(c[0].size(), 2u);
  EXPECT_EQ(c[0][0].settings, "{}");
  EXPECT_DOUBLE_EQ(c[0][0].params.get<double>("learning_rate", 0), 0.01);
  EXPECT_EQ(c[0][1].settings, "{learning_rate: 0.05}");
  EXPECT_DOUBLE_EQ(c[0][1].params.get<double>("learning_rate", 0), 0.05);
  EXPECT_DOUBLE_EQ(c[0][1].params.get<double>("lambda", 0), 0.02);  // kept from the base
  ASSERT_EQ(c[1].size(), 1u);  // not in the grid: its base settings
  EXPECT_EQ(c[1][0].settings, "{}");
  EXPECT_EQ(load_grid({}, base, {"dcf"})[0].size(), 1u);  // no grid at all
}

TEST(Folds, BadGridsAreRefusedNamingTheProblem) {
  const std::vector<std::string> trackers = {"dcf", "opencv-kcf"};
  aerie::test::expect_refusals(
      [&](const std::string& text) { load_grid(aerie::util::Config::parse(text, "grid.yaml"), {}, trackers); },
      {{"nosuch:\n  - {}\n", "grid.yaml: unknown tracker 'nosuch'"},
       {"opencv-csrt:\n  - {}\n", "tracker 'opencv-csrt' is not among the trackers run"},
       {"dcf:\n  - {nosuch: 1}\n", "grid.yaml:dcf[0]: unknown parameter 'nosuch' for tracker 'dcf'"},
       {"dcf:\n  - {}\n  - {cell: 100}\n", "grid.yaml:dcf[1]: key 'cell' = 100 is outside its valid range"},
       {"opencv-kcf:\n  - {padding: 2}\n", "unknown parameter 'padding' for tracker 'opencv-kcf'"},
       {"dcf: {lambda: 0.01}\n", "grid.yaml:dcf: expected a non-empty list"},
       {"dcf: []\n", "grid.yaml:dcf: expected a non-empty list"},
       {"dcf:\n  - 3\n", "grid.yaml:dcf[0]: a candidate is a map of parameters"},
       {"- dcf\n", "grid.yaml: expected a map of tracker name"}});
}
