// The subcommands; each parses its options and calls one pipeline.
#pragma once

namespace portcal {

int DatabaseCreatorCommand(int argc, char** argv);
int DatabaseConverterCommand(int argc, char** argv);
int DatabaseMergerCommand(int argc, char** argv);
int PosePriorImporterCommand(int argc, char** argv);
int ModelConverterCommand(int argc, char** argv);
int ImageUndistorterCommand(int argc, char** argv);
int ProjectPointsCommand(int argc, char** argv);
int SynthesizeCommand(int argc, char** argv);
int TargetExtractorCommand(int argc, char** argv);
int CameraCalibratorCommand(int argc, char** argv);
int HousingCalibratorCommand(int argc, char** argv);
int StereoCalibratorCommand(int argc, char** argv);
int CalibrationEvaluatorCommand(int argc, char** argv);
int FeatureExtractorCommand(int argc, char** argv);
int FeatureMaskerCommand(int argc, char** argv);
int ExhaustiveMatcherCommand(int argc, char** argv);
int SequentialMatcherCommand(int argc, char** argv);
int SpatialMatcherCommand(int argc, char** argv);
int RefractiveMapperCommand(int argc, char** argv);
int HierarchicalMapperCommand(int argc, char** argv);
int CalibrationSubsetSelectorCommand(int argc, char** argv);
int RefractiveBundleAdjusterCommand(int argc, char** argv);
int AutoCalibratorCommand(int argc, char** argv);
int CrossCheckCommand(int argc, char** argv);
int LiveCalibratorCommand(int argc, char** argv);
int PoseSuggesterCommand(int argc, char** argv);

}  // namespace portcal
