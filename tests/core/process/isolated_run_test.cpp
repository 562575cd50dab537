// core/process/isolated_run.h: the child's fate is reported, the caller
// lives through a crash, and a stuck child is stopped at the limit.

#include "core/process/isolated_run.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <csignal>
#include <cstdlib>
#include <stdexcept>
#include <thread>

namespace mmm::process {
namespace {

using std::chrono::seconds;

TEST(IsolatedRunTest, WorkThatReturnsOrThrowsComesThrough) {
  EXPECT_TRUE(run_isolated([] {}, seconds(30)).came_through);
  const IsolatedOutcome thrown =
      run_isolated([] { throw std::runtime_error("refused"); }, seconds(30));
  EXPECT_TRUE(thrown.came_through);
  EXPECT_EQ(thrown.description(), "came through");
}

TEST(IsolatedRunTest, AnAbortOrACrashEndsOnlyTheChild) {
  const IsolatedOutcome aborted = run_isolated([] { std::abort(); }, seconds(30));
  EXPECT_FALSE(aborted.came_through);
  EXPECT_EQ(aborted.signal, SIGABRT);
  EXPECT_THAT(aborted.description(), ::testing::HasSubstr("crashed (SIGABRT"));
  const IsolatedOutcome raised = run_isolated([] { std::raise(SIGSEGV); }, seconds(30));
  EXPECT_EQ(raised.signal, SIGSEGV);
  const IsolatedOutcome exited = run_isolated([] { std::_Exit(3); }, seconds(30));
  EXPECT_FALSE(exited.came_through);
  EXPECT_EQ(exited.exit_code, 3);
  EXPECT_EQ(exited.description(), "ended with exit status 3");
}

TEST(IsolatedRunTest, AChildPastTheLimitIsStopped) {
  const IsolatedOutcome stuck =
      run_isolated([] { std::this_thread::sleep_for(seconds(60)); }, seconds(1));
  EXPECT_FALSE(stuck.came_through);
  EXPECT_TRUE(stuck.timed_out);
  EXPECT_THAT(stuck.description(), ::testing::HasSubstr("time limit"));
}

TEST(IsolatedRunTest, WhatTheChildChangesStaysInTheChild) {
  int value = 1;
  EXPECT_TRUE(run_isolated([&value] { value = 2; }, seconds(30)).came_through);
  EXPECT_EQ(value, 1);
}

}  // namespace
}  // namespace mmm::process
