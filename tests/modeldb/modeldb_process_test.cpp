// What other processes see: a writer killed with SIGKILL in the middle of a transaction (fork + kill) leaves
// the earlier library intact; a reader loads while a writer is in the middle of adding (write-ahead log).
// No renderer in this program: children are forked from a process without GL threads.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "modeldb/model_database.h"
#include "modeldb/model_library.h"
#include "modeldb/sql.h"
#include "modeldb_test_util.h"
#include "support/test_data.h"

namespace ecv {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// A one-byte message between the processes of a test.
class Pipe {
 public:
  Pipe() {
    if (pipe(ends_) != 0) ADD_FAILURE() << "pipe";
  }
  ~Pipe() {
    close(ends_[0]);
    close(ends_[1]);
  }
  void Send() const { (void)!write(ends_[1], "x", 1); }
  bool Receive() const {
    char byte = 0;
    return read(ends_[0], &byte, 1) == 1;
  }

 private:
  int ends_[2] = {-1, -1};
};

// A child process; killed and reaped when the test leaves early, so that none outlives it.
class Child {
 public:
  explicit Child(pid_t pid) : pid_(pid) {}
  ~Child() {
    if (pid_ <= 0) return;
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  void Kill() const { kill(pid_, SIGKILL); }

  // Exit code (-1 when killed by a signal); `killed` tells whether SIGKILL ended it.
  int Wait(bool* killed = nullptr) {
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
    if (killed != nullptr) *killed = WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

 private:
  pid_t pid_;
};

// Runs `work` in a child process that exits 0 when it returns and 1 when it throws.
template <typename Work>
pid_t Fork(Work work) {
  const pid_t pid = fork();
  if (pid == 0) {
    try {
      work();
    } catch (...) {
      _exit(1);
    }
    _exit(0);
  }
  return pid;
}

TEST(ModeldbProcesses, SigkillInTheMiddleOfAReplacementLeavesTheEarlierLibrary) {
  test::TemporaryDirectory directory;
  const std::string path = directory.File("lib.sqlite");
  const ModelRecord a = test::SyntheticModel("a", 4, 300, 1);
  const ModelRecord b = test::SyntheticModel("b", 3, 300, 2);
  {
    ModelDatabase database(path, OpenMode::kCreate);
    database.AddModel(a);
    database.AddModel(b);
  }
  // The child replaces "a" with a larger model; after half of its views are written (inside the transaction)
  // it tells us and waits to be killed.
  Pipe half_written;
  Child child(Fork([&] {
    ModelDatabase database(path, OpenMode::kReadWrite);
    database.AddModel(test::SyntheticModel("a", 10, 2000, 3), [&](int done, int) {
      if (done != 5) return;
      half_written.Send();
      pause();
    });
  }));
  ASSERT_TRUE(half_written.Receive());
  const uintmax_t wal_bytes = fs::file_size(path + "-wal");
  child.Kill();
  bool killed = false;
  child.Wait(&killed);
  ASSERT_TRUE(killed);
  // The library had no log (closed cleanly); what is there now is the child's uncommitted pages.
  EXPECT_GT(wal_bytes, 1000000U) << "the child had begun writing its views to the log";

  ModelDatabase database(path, OpenMode::kReadWrite);
  const VerifyReport report = database.Verify();
  EXPECT_TRUE(report.ok()) << (report.ok() ? "" : report.problems.front());
  const std::vector<StoredModel> loaded = database.LoadModels();
  ASSERT_EQ(loaded.size(), 2U);
  EXPECT_EQ(test::CompareViews(a.views, loaded[0].record.views), "") << "the earlier a";
  EXPECT_EQ(test::CompareViews(b.views, loaded[1].record.views), "");
  database.AddModel(test::SyntheticModel("c", 1, 10, 4));  // and it can be written again
  EXPECT_EQ(database.ListModels().size(), 3U);
}

TEST(ModeldbProcesses, SigkillDuringACliBuildKeepsTheModelsAlreadyStored) {
  test::TemporaryDirectory directory;
  const std::string path = directory.File("lib.sqlite");
  ModelDatabase(path, OpenMode::kCreate).AddModel(test::SyntheticModel("earlier", 2, 100, 1));
  int output[2];
  ASSERT_EQ(pipe(output), 0);
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(output[1], STDERR_FILENO);
    close(output[0]);
    // Half the YCB-Video camera (the synthetic model was made with the full one: same features, any camera).
    execl(ECV_CLI_PATH, "ecvpose", "modeldb", "build", test::DemoMeshDirectory().c_str(), "--db", path.c_str(),
          "--views", "2", "--size", "320x240", "--camera", "533.389,533.7435,156.24345,120.40545", nullptr);
    _exit(127);
  }
  Child child(pid);
  close(output[1]);
  // Kill once the second model is being built: the first is stored, the second is not.
  std::string text;
  char buffer[256];
  for (ssize_t n; text.find("[2/3] 004_sugar_box: view 1/2") == std::string::npos &&
                  (n = read(output[0], buffer, sizeof(buffer))) > 0;) {
    text.append(buffer, static_cast<size_t>(n));
  }
  child.Kill();
  close(output[0]);
  bool killed = false;
  child.Wait(&killed);
  ASSERT_TRUE(killed) << text;
  ASSERT_THAT(text, HasSubstr("[1/3] 003_cracker_box: stored"));

  const ModelDatabase database(path, OpenMode::kReadOnly);
  EXPECT_TRUE(database.Verify().ok());
  std::vector<std::string> names;
  for (const ModelSummary& model : database.ListModels()) names.push_back(model.name);
  EXPECT_EQ(names, std::vector<std::string>({"003_cracker_box", "earlier"}));
}

TEST(ModeldbProcesses, AReaderLoadsWhileAWriterIsInTheMiddleOfAnAdd) {
  test::TemporaryDirectory directory;
  const std::string path = directory.File("lib.sqlite");
  const ModelRecord a = test::SyntheticModel("a", 3, 200, 1);
  const ModelRecord b = test::SyntheticModel("b", 4, 500, 2);
  ModelDatabase(path, OpenMode::kCreate).AddModel(a);
  Pipe in_transaction, go_on;
  Child writer(Fork([&] {
    ModelDatabase database(path, OpenMode::kReadWrite);
    database.AddModel(b, [&](int done, int) {
      if (done != 2) return;
      in_transaction.Send();
      go_on.Receive();
    });
  }));
  ASSERT_TRUE(in_transaction.Receive());

  // The writer holds the write lock: another writer that will not wait is refused...
  ModelDatabaseOptions no_waiting;
  no_waiting.busy_timeout_ms = 0;
  try {
    ModelDatabase(path, OpenMode::kReadWrite, no_waiting).AddModel(test::SyntheticModel("c", 1, 10, 3));
    ADD_FAILURE() << "a second writer got the lock";
  } catch (const SqlError& error) {
    EXPECT_EQ(error.kind(), SqlErrorKind::kBusy) << error.what();
  }
  // ...while a reader that will not wait either loads the library as it was before the writer began.
  const ModelDatabase reader(path, OpenMode::kReadOnly, no_waiting);
  const std::vector<StoredModel> before = reader.LoadModels();
  ASSERT_EQ(before.size(), 1U);
  EXPECT_EQ(test::CompareViews(a.views, before[0].record.views), "");
  EXPECT_TRUE(reader.Verify().ok());
  EXPECT_EQ(ModelLibrary::Load(path).models().size(), 1U);

  go_on.Send();
  EXPECT_EQ(writer.Wait(), 0);
  const std::vector<StoredModel> after = reader.LoadModels();
  ASSERT_EQ(after.size(), 2U);
  EXPECT_EQ(test::CompareViews(b.views, after[1].record.views), "");
  const ModelLibrary library = ModelLibrary::Load(path);
  ASSERT_EQ(library.models().size(), 2U);
  EXPECT_EQ(library.models()[1].matchers.size(), 4U);
}

}  // namespace
}  // namespace ecv
