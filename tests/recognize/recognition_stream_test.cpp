// The streaming rules without a recognizer: which frames of a stream search every model, which stream settings are
// refused, how the threads are shared when the search runs beside the tracking, and how a failure of the search
// thread reaches the caller.

#include <atomic>
#include <chrono>
#include <future>
#include <stdexcept>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "recognize/background_search.h"
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

TEST(StreamOptions, SearchingBesideTheTrackingNeedsTracking) {
  StreamOptions options;
  options.search_beside = true;
  try {
    options.Check();
    FAIL() << "search_beside without tracking accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()), "stream options: search_beside: expected tracking as well (track)");
  }
  options.track = true;
  EXPECT_NO_THROW(options.Check());
  options.search_every = 3;  // a search started at most every third frame
  EXPECT_NO_THROW(options.Check());
}

TEST(StreamOptions, BesideTheTrackingTheSearchTakesTheSmallerHalfOfTheThreads) {
  StreamOptions stream;
  stream.track = true;
  RecognizerOptions options;
  for (const auto& [threads, track, search] :
       std::vector<std::tuple<int, int, int>>{{1, 1, 1}, {2, 1, 1}, {3, 2, 1}, {8, 4, 4}}) {
    options.threads = threads;
    stream.search_beside = false;
    EXPECT_EQ(ShareThreads(options, stream).track.threads, threads);
    stream.search_beside = true;
    const StreamRecognizerOptions shared = ShareThreads(options, stream);
    EXPECT_EQ(shared.track.threads, track) << threads;
    EXPECT_EQ(shared.search.threads, search) << threads;
  }
}

RgbdFrame SmallFrame() {
  RgbdFrame frame;
  frame.color = cv::Mat(4, 4, CV_8UC3, cv::Scalar(0, 0, 0));
  frame.depth = cv::Mat(4, 4, CV_32FC1, cv::Scalar(1.0));
  frame.name = "small.json";
  return frame;
}

// What TakeFinished gives within 30 s: the message of the failure it raises, else what it found.
std::string FailureOf(BackgroundSearch* search) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (std::chrono::steady_clock::now() < deadline) {
    try {
      if (search->TakeFinished()) return "a finished search";
    } catch (const BackgroundSearchError& error) {
      return error.what();
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return "nothing in 30 s";
}

TEST(BackgroundSearch, AFailureOfItsThreadIsRaisedInTheCallersAndTheNextOfferStartsANewOne) {
  std::promise<void> go;
  const std::shared_future<void> released = go.get_future().share();
  std::atomic<int> made{0};
  BackgroundSearch search([&]() -> std::unique_ptr<Recognizer> {
    ++made;
    released.wait();
    throw std::runtime_error("no GL context here");
  });
  EXPECT_TRUE(search.Offer(SmallFrame(), 7));
  EXPECT_FALSE(search.Offer(SmallFrame(), 8));  // one frame at a time
  EXPECT_FALSE(search.TakeFinished().has_value());
  go.set_value();
  EXPECT_EQ(FailureOf(&search), "search beside the tracking, frame small.json: no GL context here");
  EXPECT_TRUE(search.Offer(SmallFrame(), 9));
  EXPECT_EQ(FailureOf(&search), "search beside the tracking, frame small.json: no GL context here");
  EXPECT_EQ(made.load(), 2);
}

TEST(BackgroundSearch, RefusesNoFactoryAndStopsAnIdleThread) {
  EXPECT_THROW(BackgroundSearch{RecognizerFactory()}, InputError);
  BackgroundSearch never_offered([]() -> std::unique_ptr<Recognizer> { throw std::logic_error("not made"); });
  EXPECT_FALSE(never_offered.TakeFinished().has_value());  // no thread: nothing made, nothing failed
}

}  // namespace
}  // namespace ecv
