// SPDX-License-Identifier: GPL-3.0-or-later
// Compiles the tests' precompiled header (tests/CMakeLists.txt, asperity_test_pch) once for
// every test executable; nothing of its own.
