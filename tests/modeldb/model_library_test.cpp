// Loading a library for recognition: all models or a subset, with one matcher per view built once.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/error.h"
#include "modeldb/model_library.h"
#include "modeldb_test_util.h"
#include "support/test_data.h"

namespace ecv {
namespace {

using ::testing::HasSubstr;

class Library : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = directory_.File("lib.sqlite");
    ModelDatabase database(path_, OpenMode::kCreate);
    for (int i = 0; i < 3; ++i) {
      ModelRecord model = test::SyntheticModel("m" + std::to_string(i), 2 + i, 300, static_cast<uint32_t>(i));
      model.features.descriptor.max_neighbours = 40;  // settings other than the defaults travel with the library
      database.AddModel(model);
    }
    database.SetColorMatrix("m1", {Eigen::Matrix3d::Identity() * 1.1, 0.02, "test", ""});
  }
  test::TemporaryDirectory directory_;
  std::string path_;
};

TEST_F(Library, LoadsEveryModelWithAMatcherPerView) {
  LibraryLoadOptions options;
  options.threads = 2;
  const ModelLibrary library = ModelLibrary::Load(path_, options);
  ASSERT_EQ(library.models().size(), 3U);
  EXPECT_EQ(library.NumViews(), 2 + 3 + 4);
  EXPECT_EQ(library.NumDescriptors(), 9LL * 240);
  EXPECT_EQ(library.feature_settings().descriptor.max_neighbours, 40);
  EXPECT_FALSE(library.Find("m0")->color_matrix.has_value());
  EXPECT_DOUBLE_EQ(library.Find("m1")->color_matrix->model_to_scene(0, 0), 1.1);
  EXPECT_EQ(library.Find("m9"), nullptr);
  // Each view's matcher indexes that view: its own descriptors find themselves at distance 0.
  for (const LibraryModel& model : library.models()) {
    ASSERT_EQ(model.matchers.size(), model.record.views.size());
    for (size_t v = 0; v < model.record.views.size(); ++v) {
      const ModelView& view = model.record.views[v];
      const std::vector<DescriptorMatch> matches = model.matchers[v]->Match(view.primitives, view.descriptors);
      ASSERT_EQ(matches.size(), static_cast<size_t>(view.descriptors.values.rows));
      for (const DescriptorMatch& match : matches) {
        ASSERT_EQ(match.train, match.query) << model.record.name << " view " << v;
        ASSERT_EQ(match.distance, 0.0F);
      }
    }
  }
  EXPECT_GE(library.timings().read_ms, 0.0);
}

TEST_F(Library, MatchesIntoTheWholeLibraryWithOneIndex) {
  LibraryLoadOptions options;
  options.build_matchers = false;
  options.build_library_index = true;
  const ModelLibrary library = ModelLibrary::Load(path_, options);
  EXPECT_TRUE(library.models()[0].matchers.empty());
  // A view's own descriptors (random, so unique in the library) find themselves: model, view and primitive.
  for (size_t m = 0; m < library.models().size(); ++m) {
    const ModelView& view = library.models()[m].record.views.back();
    const std::vector<LibraryMatch> matches = library.MatchLibrary(view.primitives, view.descriptors);
    ASSERT_EQ(matches.size(), static_cast<size_t>(view.descriptors.values.rows));
    for (const LibraryMatch& match : matches) {
      ASSERT_EQ(match.model, static_cast<int>(m));
      ASSERT_EQ(match.view, static_cast<int>(library.models()[m].record.views.size()) - 1);
      ASSERT_EQ(match.primitive, match.query);
      ASSERT_EQ(match.distance, 0.0F);
    }
  }
  options.build_library_index = false;
  const ModelLibrary without = ModelLibrary::Load(path_, options);
  EXPECT_THROW(without.MatchLibrary({}, {}), std::logic_error);
}

TEST_F(Library, LoadsASubsetAndNamesAnUnknownModel) {
  LibraryLoadOptions options;
  options.names = {"m2", "m0"};
  options.build_matchers = false;
  const ModelLibrary library = ModelLibrary::Load(path_, options);
  ASSERT_EQ(library.models().size(), 2U);
  EXPECT_EQ(library.models()[0].record.name, "m2");
  EXPECT_TRUE(library.models()[0].matchers.empty());
  options.names = {"m0", "nope"};
  try {
    ModelLibrary::Load(path_, options);
    ADD_FAILURE() << "no error for an unknown model";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("\"nope\""));
    EXPECT_THAT(error.what(), HasSubstr("m0, m1, m2"));
  }
  options.threads = 0;
  EXPECT_THROW(ModelLibrary::Load(path_, options), InputError);
}

}  // namespace
}  // namespace ecv
