// The subcommands; each parses its options and calls one pipeline.
#pragma once

namespace portcal {

int RunDatabaseCreator(int argc, char** argv);
int RunPosePriorImporter(int argc, char** argv);
int RunModelConverter(int argc, char** argv);
int RunProjectPoints(int argc, char** argv);
int RunSynthesize(int argc, char** argv);
int RunTargetExtractor(int argc, char** argv);
int RunCameraCalibrator(int argc, char** argv);
int RunHousingCalibrator(int argc, char** argv);
int RunStereoCalibrator(int argc, char** argv);
int RunFeatureExtractor(int argc, char** argv);
int RunFeatureMasker(int argc, char** argv);
int RunExhaustiveMatcher(int argc, char** argv);
int RunSequentialMatcher(int argc, char** argv);
int RunSpatialMatcher(int argc, char** argv);
int RunRefractiveMapper(int argc, char** argv);
int RunRefractiveBundleAdjuster(int argc, char** argv);
int RunAutoCalibrator(int argc, char** argv);
int RunCrossCheck(int argc, char** argv);

}  // namespace portcal
