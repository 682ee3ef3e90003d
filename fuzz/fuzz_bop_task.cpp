// BOP's task files, chosen by the first byte: even, a targets file (ReadBopTargets, then GroupBopTargets); odd, a
// results CSV (ReadBopResults) of a library with obj_ids 1 and 5.

#include "fuzz_util.h"
#include "recognize/bop_task.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  if (data[0] % 2 == 0) {
    const std::string path = (ecv::fuzz::ScratchDir() / "test_targets_bop19.json").string();
    ecv::fuzz::WriteFile(path, text);
    ecv::fuzz::ExpectOnlyInputErrors([&] { ecv::GroupBopTargets(ecv::ReadBopTargets(path), path); });
  } else {
    const std::string path = (ecv::fuzz::ScratchDir() / "results.csv").string();
    ecv::fuzz::WriteFile(path, text);
    ecv::fuzz::ExpectOnlyInputErrors([&] {
      ecv::ReadBopResults(path, {{1, "002_master_chef_can"}, {5, "obj_000005"}});
    });
  }
  return 0;
}
