// navview_make_test_tiles DIR LAT LON Z0 Z1 RADIUS_M: the test tiles of tile_fixture.h for the
// shell tests of the map's tile layer (navsim render --tiles, the URL source and its cache).
#include <cstdio>
#include <cstdlib>
#include <string>

#include "tile_fixture.h"

int main(int argc, char **argv) {
  if (argc != 7) {
    std::fprintf(stderr, "usage: navview_make_test_tiles DIR LAT LON Z0 Z1 RADIUS_M\n");
    return 2;
  }
  std::string err;
  const int n = tilefix::MakeTiles(argv[1], std::atof(argv[2]), std::atof(argv[3]), std::atoi(argv[4]),
                                   std::atoi(argv[5]), std::atof(argv[6]), &err);
  if (n < 0) {
    std::fprintf(stderr, "navview_make_test_tiles: %s\n", err.c_str());
    return 1;
  }
  std::printf("%d tiles per zoom level at most in %s/xyz and %s/tiles.mbtiles\n", n, argv[1], argv[1]);
  return 0;
}
