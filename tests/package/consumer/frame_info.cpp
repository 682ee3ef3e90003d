#include <iostream>

#include <core/frame.h>
#include <io/frame_io.h>

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  ecv::FrameSpec spec;
  spec.positional = argv[1];
  const ecv::LoadedFrame loaded = ecv::LoadFrame(spec);
  std::cout << loaded.rgbd.camera.fx << " " << loaded.ground_truth.size() << "\n";
  return 0;
}
