// SPDX-License-Identifier: Apache-2.0
#pragma once
// Counting heap allocations in a test program, to prove a real-time path allocation-free. Linking
// allocation_counter.cpp replaces the global operator new/delete of the whole program; they count only between
// start_counting_allocations() and stop_counting_allocations(), so other tests are unaffected.
//
// Under AddressSanitizer or ThreadSanitizer the sanitizer owns operator new/delete (some allocations reach its own
// operator new, and our free() of them would be reported as a mismatch), so nothing is replaced or counted there
// (IMPETUS_COUNT_ALLOCATIONS is 0) and the tests that count are compiled out: the plain Release build proves it.

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define IMPETUS_COUNT_ALLOCATIONS 0
#else
#define IMPETUS_COUNT_ALLOCATIONS 1
#endif

namespace impetus::test {

// Starts counting from zero. Not reentrant: one counting section at a time, on any thread.
void start_counting_allocations();
// Stops counting; returns the allocations made (by any thread) since start_counting_allocations().
long stop_counting_allocations();

}  // namespace impetus::test
