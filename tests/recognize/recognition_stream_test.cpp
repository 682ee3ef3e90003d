// The streaming rules without a recognizer: which frames of a stream search every model, and which stream settings
// are refused.

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "recognize/recognition_stream.h"

namespace ecv {
namespace {

// 'A' for a frame that searches every model, 'l' for one that searches lost tracks only.
std::string Scopes(SearchSchedule* schedule, int frames) {
  std::string scopes;
  for (int i = 0; i < frames; ++i) scopes += schedule->Next() == SearchScope::kAllModels ? 'A' : 'l';
  return scopes;
}

TEST(SearchSchedule, SearchesEveryModelInTheFirstFrameAndEveryNthAfterIt) {
  SearchSchedule every_frame;
  EXPECT_EQ(Scopes(&every_frame, 5), "AAAAA");
  SearchSchedule every_third(3);
  EXPECT_EQ(Scopes(&every_third, 8), "AllAllAl");
}

TEST(SearchSchedule, AfterAResetTheNextFrameSearchesEveryModelAndTheCountStartsFromIt) {
  SearchSchedule schedule(4);
  EXPECT_EQ(Scopes(&schedule, 2), "Al");
  schedule.Reset();  // a broken frame, or a new video
  EXPECT_EQ(Scopes(&schedule, 6), "AlllAl");
}

TEST(SearchSchedule, RefusesLessThanOneFrame) {
  EXPECT_THROW(SearchSchedule(0), InputError);
}

TEST(StreamOptions, SearchingEveryNthFrameNeedsTracking) {
  StreamOptions options;
  EXPECT_NO_THROW(options.Check());
  options.search_every = 3;
  try {
    options.Check();
    FAIL() << "search_every 3 without tracking accepted";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("search_every"), std::string::npos) << error.what();
  }
  options.track = true;
  EXPECT_NO_THROW(options.Check());
  options.search_every = 0;
  EXPECT_THROW(options.Check(), InputError);
}

}  // namespace
}  // namespace ecv
