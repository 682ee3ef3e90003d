#include "recognize/background_search.h"

#include <exception>
#include <utility>

#include "core/error.h"

namespace ecv {
namespace {

// The frame with images of its own: the caller may reuse its buffers once the offer returns.
RgbdFrame Copy(const RgbdFrame& frame) {
  RgbdFrame copy = frame;
  copy.color = frame.color.clone();
  copy.depth = frame.depth.clone();
  return copy;
}

std::string What(const std::exception_ptr& failure) {
  try {
    std::rethrow_exception(failure);
  } catch (const std::exception& error) {
    return error.what();
  } catch (...) {
    return "an exception that is no std::exception";
  }
}

}  // namespace

BackgroundSearch::BackgroundSearch(RecognizerFactory make_recognizer) : make_recognizer_(std::move(make_recognizer)) {
  if (!make_recognizer_) ThrowInputError("background search", "make_recognizer", "a factory of the searcher");
}

BackgroundSearch::~BackgroundSearch() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

bool BackgroundSearch::Offer(const RgbdFrame& frame, int64_t number) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (job_ || searching_ || failure_) return false;
  }
  // Only this thread offers: the searcher stays idle while the frame is copied outside the lock.
  Job job{Copy(frame), number, 0};
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    job.generation = generation_;
    job_ = std::move(job);
  }
  if (!thread_.joinable()) thread_ = std::thread(&BackgroundSearch::Run, this);
  wake_.notify_one();
  return true;
}

std::optional<FinishedSearch> BackgroundSearch::TakeFinished() {
  std::unique_lock<std::mutex> lock(mutex_);
  if (failure_) {
    const std::string message = std::move(*failure_);
    failure_.reset();
    lock.unlock();
    thread_.join();  // it has ended, or is ending
    throw BackgroundSearchError(message);
  }
  std::optional<FinishedSearch> finished = std::move(finished_);
  finished_.reset();
  return finished;
}

void BackgroundSearch::Forget() {
  const std::lock_guard<std::mutex> lock(mutex_);
  ++generation_;
  job_.reset();
  finished_.reset();
}

void BackgroundSearch::Run() {
  std::unique_ptr<Recognizer> recognizer;  // made, used and destroyed on this thread (after the lock is released)
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    wake_.wait(lock, [this] { return stop_ || job_.has_value(); });
    if (stop_) return;
    const Job job = std::move(*job_);
    job_.reset();
    searching_ = true;
    lock.unlock();
    std::optional<FinishedSearch> finished;
    std::exception_ptr failure;
    try {
      if (!recognizer) recognizer = make_recognizer_();
      RecognitionResult result = recognizer->Recognize(job.frame);
      const auto total = result.timings_ms.find("total");
      finished = FinishedSearch{std::move(result.detections), job.number,
                                total != result.timings_ms.end() ? total->second : 0.0};
    } catch (...) {
      failure = std::current_exception();
    }
    lock.lock();
    searching_ = false;
    if (failure) {
      const std::string frame = job.frame.name.empty() ? "number " + std::to_string(job.number) : job.frame.name;
      failure_ = "search beside the tracking, frame " + frame + ": " + What(failure);
      return;
    }
    if (job.generation == generation_) finished_ = std::move(finished);
  }
}

}  // namespace ecv
