// Tests of parallel: chunks, error order, and that results do not depend on the thread count.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "kin2grf/error.hpp"
#include "kin2grf/io/opensim.hpp"
#include "kin2grf/kinematics/filter.hpp"
#include "kin2grf/parallel.hpp"
#include "kin2grf/pipeline.hpp"
#include "test_support.hpp"

using namespace kin2grf;

TEST(Parallel, ChunksCoverTheRangeInOrderAndRespectTheMinimum) {
  EXPECT_EQ(chunk_bounds(1000, 100, 4), (std::vector<std::size_t>{0, 250, 500, 750, 1000}));
  EXPECT_EQ(chunk_bounds(250, 100, 4), (std::vector<std::size_t>{0, 125, 250}));  // 2 chunks of >= 100
  EXPECT_EQ(chunk_bounds(99, 100, 4), (std::vector<std::size_t>{0, 99}));
  EXPECT_EQ(chunk_bounds(1000, 1, 1), (std::vector<std::size_t>{0, 1000}));
  EXPECT_EQ(chunk_bounds(0, 1, 3), (std::vector<std::size_t>{0, 0}));
}

TEST(Parallel, TheEarliestChunksErrorIsTheOneReported) {
  const ThreadCountScope four(4);
  std::atomic<int> ran{0};
  try {
    for_chunks(400, 1, [&](std::size_t chunk, std::size_t, std::size_t) {
      ++ran;
      if (chunk == 1 || chunk == 3) throw std::runtime_error("chunk " + std::to_string(chunk));
    });
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "chunk 1");
  }
  EXPECT_EQ(ran, 4) << "every chunk finishes before the error leaves";
}

TEST(Parallel, ALoopInsideAChunkRunsOnItsThread) {
  const ThreadCountScope two(2);
  std::atomic<int> inner{0};
  for_chunks(100, 1, [&](std::size_t, std::size_t, std::size_t) { inner += thread_count(); });
  EXPECT_EQ(inner, 2);
  EXPECT_EQ(thread_count(), 2);
}

namespace {
// Long enough that rows are read in several chunks (at least kMinSecondsPerChunk each).
constexpr int kLongRows = 300000;

std::string trc_text(int frames, int bad_frame_a = -1, int bad_frame_b = -1) {
  std::string s = "PathFileType\t4\t(X/Y/Z)\tx.trc\nDataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\n";
  s += "100\t100\t" + std::to_string(frames) + "\t1\tmm\nFrame#\tTime\tA\t\t\n\t\tX1\tY1\tZ1\n";
  s.reserve(s.size() + 40 * static_cast<std::size_t>(frames));
  for (int i = 0; i < frames; ++i) {
    char row[96];  // (snprintf, not string sums: GCC 12 warns falsely on those, -Wrestrict)
    if (i == bad_frame_a || i == bad_frame_b) std::snprintf(row, sizeof row, "%d\t%.2f\toops\t1\t2\n", i + 1, i * 0.01);
    else std::snprintf(row, sizeof row, "%d\t%.2f\t%.3f\t%d\t%s\n", i + 1, i * 0.01, 0.5 * (i % 1000) + 0.123, i % 977, i % 7 ? "3.25" : "");
    s += row;
  }
  return s;
}
}  // namespace

TEST(Parallel, ChunksOnlyWorkWorthAThread) {
  EXPECT_NEAR(static_cast<double>(min_chunk_for(10e-6)), 500.0, 1.0);  // 5 ms of 10 us frames
  EXPECT_EQ(min_chunk_for(1.0), 1u);
  EXPECT_EQ(min_chunk_for(0.0), 1u);
  const ThreadCountScope four(4);
  EXPECT_EQ(chunk_bounds(510, min_chunk_for(10e-6), 4).size(), 2u) << "a 510-frame solve stays on one thread";
  EXPECT_EQ(chunk_bounds(12000, min_chunk_for(10e-6), 4).size(), 5u);
}

TEST(Parallel, TrcRowsReadOnManyThreadsAreTheSameAndTheFirstBadLineIsNamed) {
  const std::string text = trc_text(kLongRows);
  ASSERT_GT(chunk_bounds(kLongRows, min_chunk_for(5e-9 * static_cast<double>(text.size()) / kLongRows), 4).size(), 2u)
      << "the test must read in several chunks";
  MarkerTrajectories one, many;
  {
    const ThreadCountScope t(1);
    one = parse_trc(text, "x.trc");
  }
  {
    const ThreadCountScope t(4);
    many = parse_trc(text, "x.trc");
  }
  ASSERT_EQ(many.frames(), kLongRows);
  EXPECT_TRUE(one.time_s.cwiseEqual(many.time_s).all());
  const auto& a = one.positions_m[0].array();
  const auto& b = many.positions_m[0].array();
  EXPECT_EQ(a.isNaN().count(), kLongRows / 7 * 3 + 3);  // every 7th row has a blank Z
  EXPECT_TRUE((a.isNaN() == b.isNaN()).all());
  EXPECT_TRUE((a.isNaN() || a == b).all());
  // Bad cells near the end of the first and of the last chunk: the error is the first one, as
  // when read in one go.
  const ThreadCountScope t(4);
  try {
    (void)parse_trc(trc_text(kLongRows, 1000, kLongRows - 10), "x.trc");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("x.trc:1006:"), std::string::npos) << e.what();
  }
}

TEST(Parallel, FilteringAndEstimatingGiveTheSameNumbersOnOneOrFourThreads) {
  // Sizes that make several chunks (at least kMinSecondsPerChunk each): 500,000 rows x 8 columns
  // to filter; 24 columns of 6,000 frames for the residual analysis; 2,500 frames to solve.
  const Eigen::MatrixXd x = Eigen::MatrixXd::Random(500000, 8), xr = Eigen::MatrixXd::Random(6000, 24);
  Eigen::MatrixXd y1, y4;
  double c1 = 0, c4 = 0;
  {
    const ThreadCountScope t(1);
    y1 = butterworth_filtfilt(x, 100, 6);
    c1 = residual_analysis_cutoff(butterworth_filtfilt(xr, 100, 6) + 0.01 * xr, 100, 15);
  }
  {
    const ThreadCountScope t(4);
    y4 = butterworth_filtfilt(x, 100, 6);
    c4 = residual_analysis_cutoff(butterworth_filtfilt(xr, 100, 6) + 0.01 * xr, 100, 15);
  }
  EXPECT_TRUE(y1.cwiseEqual(y4).all());
  EXPECT_EQ(c1, c4);

  SyntheticOptions so;
  so.duration_s = 25.0;
  so.flight_height_m = 0.1;  // contacts switch off and on inside the chunks
  EstimateResult r1, r4;
  {
    const ThreadCountScope t(1);
    r1 = test::run(so);
  }
  {
    const ThreadCountScope t(4);
    r4 = test::run(so);
  }
  for (int side = 0; side < 2; ++side) {
    EXPECT_TRUE(r1.feet[side].force_N.cwiseEqual(r4.feet[side].force_N).all());
    EXPECT_EQ(r1.feet[side].contact, r4.feet[side].contact);
  }
  EXPECT_TRUE(r1.joint_torque_Nm.cwiseEqual(r4.joint_torque_Nm).all());
  EXPECT_EQ(r1.iterations, r4.iterations);
  EXPECT_EQ(r1.cycled_frames, r4.cycled_frames);
}
