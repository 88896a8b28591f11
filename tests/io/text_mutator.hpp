#pragma once
// Seeded mutations of valid input text for the parser fuzz tests: byte flips, truncation,
// deleted and duplicated ranges, tokens of the format (deep nesting, huge, NaN and infinite
// numbers, wrong types, huge counts) inserted or put in place of a number.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <random>
#include <string>
#include <thread>
#include <typeinfo>
#include <vector>

#include <shapectl/io/input_error.hpp>

namespace shapectl::test {

class TextMutator {
 public:
  // `tokens`: strings of the format worth inserting (keywords, brackets, extreme numbers).
  explicit TextMutator(std::vector<std::string> tokens) : tokens_(std::move(tokens)) {}

  // One to three mutations of `text`; a third of the time just one number replaced by a
  // token, which mostly keeps the syntax and so reaches the checks behind the parser.
  std::string mutate(std::string text, std::mt19937& rng) const {
    if (rng() % 3 == 0) return replace_number(std::move(text), rng);
    const int count = 1 + static_cast<int>(rng() % 3);
    for (int m = 0; m < count; ++m) text = mutate_once(std::move(text), rng);
    return text;
  }

 private:
  static std::size_t position(const std::string& text, std::mt19937& rng) {
    return text.empty() ? 0 : rng() % (text.size() + 1);
  }

  // Start and length of a digit run (a number's mantissa) near a random spot, or length 0.
  static std::pair<std::size_t, std::size_t> number_near(const std::string& text,
                                                         std::mt19937& rng) {
    std::size_t at = text.find_first_of("0123456789", position(text, rng));
    if (at == std::string::npos) return {0, 0};
    std::size_t end = text.find_first_not_of("0123456789.eE+-", at);
    if (end == std::string::npos) end = text.size();
    return {at, end - at};
  }

  // A number replaced with a token (an extreme number or a wrong type).
  std::string replace_number(std::string text, std::mt19937& rng) const {
    const std::string& token = tokens_[rng() % tokens_.size()];
    const auto [at, length] = number_near(text, rng);
    return length == 0 ? text : text.replace(at, length, token);
  }

  std::string mutate_once(std::string text, std::mt19937& rng) const {
    const std::string& token = tokens_[rng() % tokens_.size()];
    switch (rng() % 8) {
      case 0:  // flip a byte
        if (!text.empty()) text[rng() % text.size()] = static_cast<char>(rng() % 256);
        return text;
      case 1:  // truncate
        return text.substr(0, position(text, rng));
      case 2: {  // delete a range
        const std::size_t at = position(text, rng);
        return text.erase(at, rng() % 64);
      }
      case 3: {  // duplicate a range in place
        const std::size_t at = position(text, rng);
        const std::string piece = text.substr(at, 1 + rng() % 200);
        return text.insert(at, piece);
      }
      case 4:  // insert a token
        return text.insert(position(text, rng), token);
      case 5: return replace_number(std::move(text), rng);
      case 6: {  // deep nesting of the token's first character, closed or not
        const std::string open(50 + rng() % 3000, token.empty() ? '[' : token[0]);
        return text.insert(position(text, rng), open);
      }
      default: {  // repeat one line many times
        const std::size_t at = text.rfind('\n', position(text, rng));
        const std::size_t from = at == std::string::npos ? 0 : at + 1;
        const std::size_t to = text.find('\n', from);
        const std::string line =
            text.substr(from, to == std::string::npos ? std::string::npos : to - from + 1);
        std::string repeated;
        for (std::size_t k = 0, n = 2 + rng() % 200; k < n; ++k) repeated += line;
        return text.insert(from, repeated);
      }
    }
  }

  std::vector<std::string> tokens_;
};

// How a fuzz run ended: inputs that parsed and inputs refused with InputError.
struct FuzzCounts {
  int parsed = 0;
  int refused = 0;
};

// Feeds `cases` mutations of the seeds (in turn) to `parse`; every case must parse or throw
// InputError. Any other exception fails the test naming the case; a signal kills the binary.
inline FuzzCounts fuzz_parser(const std::vector<std::string>& seeds, const TextMutator& mutator,
                              int cases, unsigned seed,
                              const std::function<void(const std::string&)>& parse) {
  std::mt19937 rng(seed);
  FuzzCounts counts;
  // A hang is a failure, not a wait for CTest's timeout: a case still running after 60 s (a
  // hundred times the slowest seen) stops the test binary with its number.
  std::atomic<int> current{-1};
  std::atomic<bool> done{false};
  std::thread watchdog([&] {
    int watched = -1;
    auto since = std::chrono::steady_clock::now();
    while (!done) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      const int now_case = current;
      if (now_case != watched) {
        watched = now_case;
        since = std::chrono::steady_clock::now();
      } else if (std::chrono::steady_clock::now() - since > std::chrono::seconds(60)) {
        std::fprintf(stderr, "fuzz case %d (seed %u) hangs: still running after 60 s\n", watched,
                     seed);
        std::abort();
      }
    }
  });
  for (int c = 0; c < cases; ++c) {
    current = c;
    const std::string text = mutator.mutate(seeds[static_cast<std::size_t>(c) % seeds.size()], rng);
    try {
      parse(text);
      ++counts.parsed;
    } catch (const InputError&) {
      ++counts.refused;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "case " << c << " (seed " << seed << "): " << typeid(e).name() << ": "
                    << e.what() << "\ninput starts: " << text.substr(0, 300);
    } catch (...) {
      ADD_FAILURE() << "case " << c << " (seed " << seed << "): a non-standard exception";
    }
  }
  done = true;
  watchdog.join();
  return counts;
}

}  // namespace shapectl::test
