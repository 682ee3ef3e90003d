#include "core/byte_neighbours.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include <immintrin.h>

#include "core/error.h"

namespace ecv {
namespace {

constexpr int kLanes = 16;         // queries per VNNI sweep: one 512-bit register of 32-bit sums
constexpr int kGroupBytes = 4;     // bytes one VNNI lane multiplies and adds
constexpr int kMaxGroups = 64;     // the VNNI kernel keeps the queries' groups of at most 256 values
constexpr float kLevels = 127.0F;  // 7 bits: a quantised row fits VNNI's signed operand

std::atomic<bool> allow_vnni{true};

bool UseVnni() {
  return ByteNeighbours::CpuHasVnni() && allow_vnni.load();
}

uint8_t Quantise(float value) {
  return static_cast<uint8_t>(std::lround(std::clamp(value, 0.0F, 1.0F) * kLevels));
}

// `values` quantised into `bytes` (groups x 4, zero-padded); returns the squared norm.
int32_t QuantiseRow(const float* values, int cols, uint8_t* bytes, int groups) {
  std::fill(bytes, bytes + groups * kGroupBytes, 0);
  int32_t norm = 0;
  for (int c = 0; c < cols; ++c) {
    bytes[c] = Quantise(values[c]);
    norm += static_cast<int32_t>(bytes[c]) * bytes[c];
  }
  return norm;
}

// The dot product of two quantised rows (groups x 4 bytes each): a plain loop.
int32_t Dot(const uint8_t* a, const uint8_t* b, int bytes) {
  int32_t sum = 0;
  for (int i = 0; i < bytes; ++i) sum += static_cast<int32_t>(a[i]) * b[i];
  return sum;
}

// The nearest row (k = 1) of each of `count` (at most 16) queries, the lowest row on a tie. The queries lie in the
// 16 lanes of one register per 4-byte group (24 registers for 96 values), and each row's group is broadcast from
// memory into the VNNI instruction: a row is read once for 16 queries. `queries`: count x groups x 4 bytes;
// writes {squared distance, row} to nearest[0 .. count).
__attribute__((target("avx512f,avx512bw,avx512vnni"))) void NearestVnni(const uint8_t* rows, const int32_t* norms,
                                                                        int row_count, const uint8_t* queries,
                                                                        const int32_t* query_norms, int count,
                                                                        int groups, std::pair<int32_t, int>* nearest) {
  __m512i lanes[kMaxGroups];  // group g of the 16 queries
  int32_t words[kLanes] = {};
  for (int g = 0; g < groups; ++g) {
    for (int q = 0; q < count; ++q) std::memcpy(&words[q], queries + (q * groups + g) * kGroupBytes, kGroupBytes);
    lanes[g] = _mm512_loadu_si512(words);
  }
  int32_t norm_words[kLanes] = {};
  std::copy(query_norms, query_norms + count, norm_words);
  const __m512i query_norm = _mm512_loadu_si512(norm_words);
  __m512i best = _mm512_set1_epi32(std::numeric_limits<int32_t>::max());
  __m512i best_row = _mm512_set1_epi32(-1);
  const size_t row_bytes = static_cast<size_t>(groups) * kGroupBytes;
  for (int r = 0; r < row_count; ++r) {
    const uint8_t* row = rows + static_cast<size_t>(r) * row_bytes;
    // Two independent sums: a single chain would wait on each instruction's latency.
    __m512i sum0 = _mm512_setzero_si512(), sum1 = _mm512_setzero_si512();
    int g = 0;
    for (; g + 2 <= groups; g += 2) {
      int32_t a, b;
      std::memcpy(&a, row + g * kGroupBytes, sizeof a);
      std::memcpy(&b, row + (g + 1) * kGroupBytes, sizeof b);
      sum0 = _mm512_dpbusd_epi32(sum0, _mm512_set1_epi32(a), lanes[g]);
      sum1 = _mm512_dpbusd_epi32(sum1, _mm512_set1_epi32(b), lanes[g + 1]);
    }
    if (g < groups) {
      int32_t a;
      std::memcpy(&a, row + g * kGroupBytes, sizeof a);
      sum0 = _mm512_dpbusd_epi32(sum0, _mm512_set1_epi32(a), lanes[g]);
    }
    const __m512i sum = _mm512_add_epi32(sum0, sum1);
    const __m512i distance =
        _mm512_sub_epi32(_mm512_add_epi32(_mm512_set1_epi32(norms[r]), query_norm), _mm512_add_epi32(sum, sum));
    const __mmask16 nearer = _mm512_cmplt_epi32_mask(distance, best);  // strictly: rows rise, a tie keeps the lower
    best = _mm512_mask_mov_epi32(best, nearer, distance);
    best_row = _mm512_mask_mov_epi32(best_row, nearer, _mm512_set1_epi32(r));
  }
  int32_t distances[kLanes], found[kLanes];
  _mm512_storeu_si512(distances, best);
  _mm512_storeu_si512(found, best_row);
  for (int q = 0; q < count; ++q) nearest[q] = {distances[q], found[q]};
}

}  // namespace

void ByteNeighbours::AllowVnni(bool allow) {
  allow_vnni = allow;
}

bool ByteNeighbours::CpuHasVnni() {
  static const bool has =
      __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vnni");
  return has;
}

ByteNeighbours::ByteNeighbours(const cv::Mat& rows) : rows_(rows.rows), cols_(rows.cols) {
  if (rows.type() != CV_32FC1 && !rows.empty()) {
    ThrowInputError("byte neighbours", "rows", "a CV_32FC1 matrix");
  }
  groups_ = (cols_ + kGroupBytes - 1) / kGroupBytes;
  const size_t row_bytes = static_cast<size_t>(groups_) * kGroupBytes;
  bytes_.resize(static_cast<size_t>(rows_) * row_bytes);
  norms_.resize(static_cast<size_t>(rows_));
  for (int row = 0; row < rows_; ++row) {
    norms_[static_cast<size_t>(row)] =
        QuantiseRow(rows.ptr<float>(row), cols_, &bytes_[static_cast<size_t>(row) * row_bytes], groups_);
  }
}

void ByteNeighbours::Search(const cv::Mat& queries, int k, cv::Mat* indices, cv::Mat* squared_distances) const {
  if (k < 1) ThrowInputError("byte neighbours search", "k", "at least 1 neighbour", std::to_string(k));
  if (queries.type() != CV_32FC1 || (queries.rows > 0 && rows_ > 0 && queries.cols != cols_)) {
    ThrowInputError("byte neighbours search", "queries", "CV_32FC1 rows of " + std::to_string(cols_) + " columns");
  }
  indices->create(queries.rows, k, CV_32SC1);
  squared_distances->create(queries.rows, k, CV_32FC1);
  const bool vnni = UseVnni();
  const size_t query_bytes = static_cast<size_t>(groups_) * kGroupBytes;
  const float unit = 1.0F / (kLevels * kLevels);
  auto write = [&](int q, int i, int32_t distance, int row) {
    indices->at<int>(q, i) = row;
    squared_distances->at<float>(q, i) =
        row >= 0 ? static_cast<float>(distance) * unit : std::numeric_limits<float>::infinity();
  };
  if (vnni && k == 1 && rows_ > 0 && groups_ <= kMaxGroups) {  // the recognizer's case: 16 queries per sweep
    std::vector<uint8_t> quantised(kLanes * query_bytes);
    int32_t norms[kLanes];
    std::pair<int32_t, int> nearest[kLanes];
    for (int first = 0; first < queries.rows; first += kLanes) {
      const int count = std::min(kLanes, queries.rows - first);
      for (int i = 0; i < count; ++i) {
        norms[i] = QuantiseRow(queries.ptr<float>(first + i), cols_, &quantised[i * query_bytes], groups_);
      }
      NearestVnni(bytes_.data(), norms_.data(), rows_, quantised.data(), norms, count, groups_, nearest);
      for (int i = 0; i < count; ++i) write(first + i, 0, nearest[i].first, nearest[i].second);
    }
    return;
  }
  std::vector<uint8_t> query(query_bytes);
  std::vector<int32_t> best_distance;
  std::vector<int> best_row;
  for (int q = 0; q < queries.rows; ++q) {
    const int32_t query_norm = QuantiseRow(queries.ptr<float>(q), cols_, query.data(), groups_);
    best_distance.clear();
    best_row.clear();
    for (int row = 0; row < rows_; ++row) {
      const int32_t distance =
          norms_[static_cast<size_t>(row)] + query_norm -
          2 * Dot(&bytes_[static_cast<size_t>(row) * query_bytes], query.data(), static_cast<int>(query_bytes));
      const bool full = static_cast<int>(best_row.size()) == k;
      if (full && distance >= best_distance.back()) continue;  // rows rise: a tie stays with the lower row
      if (full) {
        best_distance.pop_back();
        best_row.pop_back();
      }
      size_t at = best_row.size();
      while (at > 0 && distance < best_distance[at - 1]) --at;
      best_distance.insert(best_distance.begin() + static_cast<std::ptrdiff_t>(at), distance);
      best_row.insert(best_row.begin() + static_cast<std::ptrdiff_t>(at), row);
    }
    for (int i = 0; i < k; ++i) {
      const bool found = i < static_cast<int>(best_row.size());
      write(q, i, found ? best_distance[static_cast<size_t>(i)] : 0, found ? best_row[static_cast<size_t>(i)] : -1);
    }
  }
}

}  // namespace ecv
