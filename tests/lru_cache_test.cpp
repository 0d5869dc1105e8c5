// The bounded cache of the backends' derived tables (base/lru_cache.h): it never holds more
// than its capacity, drops the least recently used entry, and keeps what was just used.
#include "base/lru_cache.h"

#include <gtest/gtest.h>

#include <string>

namespace portalsim {
namespace {

TEST(LruCache, HoldsAtMostItsCapacityDroppingTheLeastRecentlyUsed) {
  LruCache<std::string, int> cache(3);
  cache["a"] = 1;
  cache["b"] = 2;
  cache["c"] = 3;
  EXPECT_EQ(cache["a"], 1);  // a is now the most recent; b the least
  cache["d"] = 4;
  EXPECT_EQ(cache.size(), 3u);
  EXPECT_FALSE(cache.contains("b"));
  EXPECT_TRUE(cache.contains("a") && cache.contains("c") && cache.contains("d"));
  // A dropped key comes back made afresh.
  EXPECT_EQ(cache["b"], 0);
  EXPECT_FALSE(cache.contains("c"));
}

TEST(LruCache, AThousandKnobSettingsKeepTheSizeBoundedAndTheLatestValid) {
  LruCache<std::string, std::string> cache(8);
  std::string* previous = nullptr;
  for (int i = 0; i < 1000; ++i) {
    std::string& v = cache["knobs=" + std::to_string(i)];
    v = "tables " + std::to_string(i);
    if (previous) {
      EXPECT_EQ(*previous, "tables " + std::to_string(i - 1)) << "the entry used last is kept";
    }
    previous = &v;
    ASSERT_LE(cache.size(), 8u);
  }
  for (int i = 992; i < 1000; ++i) EXPECT_TRUE(cache.contains("knobs=" + std::to_string(i))) << i;
}

// reserve() grows the capacity for what is used by turns (each raw grid's part of a batch)
// and never shrinks it.
TEST(LruCache, ReserveHoldsMoreAndNeverLess) {
  LruCache<int, int> cache(2);
  cache.reserve(5);
  EXPECT_EQ(cache.capacity(), 5u);
  for (int round = 0; round < 2; ++round)
    for (int k = 0; k < 5; ++k) cache[k] += 1;
  for (int k = 0; k < 5; ++k) EXPECT_EQ(cache[k], 2) << k << " was dropped and made again";
  cache.reserve(3);
  EXPECT_EQ(cache.capacity(), 5u);
}

}  // namespace
}  // namespace portalsim
