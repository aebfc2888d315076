# SPDX-License-Identifier: GPL-3.0-or-later
# Read by ctest after the discovered gtest tests (TEST_INCLUDE_FILES, tests/CMakeLists.txt): tests
# whose point is a rate, a power, an exhaustive numerical sweep or a long run at one large size,
# checked in the Release pass only (label no-sanitizer). Each one's code paths run under ASan +
# UBSan in the smaller tests named beside it, so the sanitized pass loses no path, only
# repetitions (~10-15x slower there). A renamed test is no longer matched and simply runs in both
# passes again.
set_tests_properties(
  # kolmogorov_pvalue over a dense (n, d) grid; exact and asymptotic branches and their switch:
  # KolmogorovPvalue.ClosedFormsAndLimits, .ExactReferenceValues, .ContinuityBetweenBranches
  KolmogorovPvalue.MonotoneAndInRange
  # 400 replicates of ks_one_sample under H0: KsOneSample.StatisticByHand, .PowerAgainstWrongScale
  KsOneSample.CalibratedUnderH0
  # 2 x 10^5 brute-force drops, two-sample KS per field: Orientation.MarsagliaIsHaar (the same
  # draw), KsTwoSample.AcceptsSameRejectsShift, and every contact test of test_contact
  Orientation.MarsagliaDropsHaveShoemakesContactLaw
  # 400 replicates of the Haar check: Orientation.MarsagliaIsHaar
  Orientation.MarsagliaUnitAndCalibrated
  # rejection rates of the binned KS, chi2 and LR tests: Binned.BlockBinsFeedTheSphereBootstrap,
  # .FineBinnerIsTheEdgeComparisonAndAgreesWithTheCdf, .KsDistanceIsTheEcdfAtTheBinEdgesCountedByHand
  Binned.IidCalibrationAndPowerOfKsChi2AndLr
  Binned.QuenchedBlocksTakeTheirErrorFromTheSpreadBetweenBlocks
  # the cross-check's power against a perturbed screening (two screen_body + two 2 x 10^5-direction
  # checks): ScreenBody.FacetCentresAreScreenedSoundly, Meshes/ScreenBodyLevels.NoWinnerIsScreened/*
  ScreenBody.AnUnsoundVariantIsCaughtByTheSameCrossCheck
  # issue 35 at its own size: 4 x 10^7 sampled impact drops (statistics "auto" streams only above
  # 2^25), cut by SIGTERM and resumed through the CLI; ~35 s of CPU in Release, past its 300 s
  # timeout under ASan on a loaded 2-core machine. Its paths at small sizes under ASan: the plan
  # switching the impacts off, Plan.ContactOnlySceneRunsNoImpactStage (fig4, restitution off); a
  # sampled streaming run cut and resumed, CheckpointTrust.EveryStreamingRunResumesToTheSameBits;
  # SIGTERM and --resume through the CLI, Checkpoint.SigtermThenResumeEqualsTheUninterruptedRun
  Checkpoint.AnImpactSceneWithoutRestitutionStreamsCompletesAndResumes
  # the comparison's power against three wrong rotations of 20 random bodies (FreeRotation and the
  # odeint reference on the same bodies): FreeRotation.MatchesOdeintReferenceForRandomBodies
  FreeRotation.ComparisonRejectsWrongImplementations
  # the grid against brute force at N = 10^5 (the same code at N = 1 ... 1000):
  # Sizes/GridRandom.MatchesBruteOnRandomQueries/1, /2, /3, /10, /1000
  Sizes/GridRandom.MatchesBruteOnRandomQueries/100000
  # the level sampler's law and power against a wrong law: TheoryRadii.FreshSamplerEqualsExplicitBodies
  TheoryRadii.FreshSamplerFollowsTheExactLawAndAWrongLawIsRejected
  PROPERTIES LABELS no-sanitizer)
