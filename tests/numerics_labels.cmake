# Read by CTest after the discovered tests (tests/CMakeLists.txt): the unit tests labelled
# `numerics`, which test.sh's sanitizer pass leaves out. Each is a law checked over many steps
# or meshes; the code it runs is run under the sanitizers by shorter tests (named after each).
# A name CTest does not find is ignored (a renamed test then runs in the sanitizer pass too).
set(vdmsim_numerics_tests
  # constraint contact, with friction and on the core: ConstraintContact.SmallSidewaysPushSticks,
  # ThinProbeBetweenNodesMovesTheSurface, OrganSolverContact.*, CoreSceneSnapshot.*, CoreStress.*
  ConstraintContact.FrictionlessSlideOnTheCoreHasNoTangentialForce
  ConstraintContact.DeepFrictionlessSlideKeepsTheLaws
  ConstraintContact.SlidingWithFrictionDragsWithMuTimesTheNormalForce
  ConstraintContact.LargerSidewaysPushSlips
  ConstraintContact.FrictionlessSlideHasNoTangentialForce
  # inertia on the core: the other CoreInertia.* (momentum, damping, a rewound step)
  CoreInertia.CantileverPeriodFollowsFromItsStaticSag
  OrganModels.CoreSceneWithInertiaSwingsPastItsStaticSag
  # the core's rotations under a load: the other ElasticCore.*, CoreStress.*
  ElasticCore.LoadedBendingStopsNearItsFixedPoint
  # instruments' forces and grasps: Effects.*, CoreSceneSnapshot.AGraspHeldAcross...
  InstrumentForces.AProbesForceIsItsContactForce
  InstrumentForces.AGraspAndLiftPullsTheJawsDownHarderAsItLifts
  # the membrane on a refined mesh: MembraneCapsule.StressViewFindsTheProbe...,
  # HardDeformation.CubeCompressedBy54PercentWithTheMembraneCapsule
  MembraneCapsule.FlatPunchConvergesUnderRefinement)
# Renderer tests keep their label `render`.
set(vdmsim_numerics_render_tests
  # every frame of a ported scene: the other GroundTruthOutput.*
  GroundTruthOutput.APortedInstrumentsShaftPassesItsPortInEveryFrame
  # the endoscope's golden images: the other GoldenImages.*, GroundTruthOutput.TheEndoscopes*
  GoldenImages.LaparoscopicView)
foreach(test IN LISTS vdmsim_numerics_tests)
  set_tests_properties(${test} PROPERTIES LABELS numerics)
endforeach()
foreach(test IN LISTS vdmsim_numerics_render_tests)
  set_tests_properties(${test} PROPERTIES LABELS "render;numerics")
endforeach()
