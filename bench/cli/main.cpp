#include <cstdio>
int main() {
  std::puts("bvhlab: the CLI is not built yet");
  return 0;
}
