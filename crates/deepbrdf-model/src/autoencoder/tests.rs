//! Tests of the autoencoder: presets, shapes, the spectral network before training, the
//! offset, and the configuration formats.

use burn::prelude::*;
use burn::tensor::TensorData;

use super::*;

fn device() -> Device {
    Device::default()
}

/// Table 1's strides, kernels and paddings with one or two channels per layer.
fn narrow(k: usize, channels: usize, blocks: usize, mean_offset: bool) -> AutoencoderConfig {
    AutoencoderConfig::convolutional(
        k,
        ConvolutionalConfig::new()
            .with_projection(Some(channels))
            .with_encoder_channels([channels; 3])
            .with_residual_blocks(blocks)
            .with_decoder_channels([channels; 2])
            .with_mean_offset(mean_offset),
    )
}

#[test]
fn the_presets_differ_in_architecture_only_and_share_what_the_paper_fixes() {
    let (paper, cpu) = (AutoencoderConfig::paper(10), AutoencoderConfig::cpu(10));
    // What they share: k and the leaky ReLU slope.
    assert_eq!((paper.latent, paper.negative_slope), (cpu.latent, cpu.negative_slope));
    assert_eq!(paper.latent, 10);
    // What differs: Table 1's convolutions against the spectral network, nothing else.
    let Architecture::Convolutional(table1) = &paper.architecture else {
        panic!("the paper preset is convolutional: {paper}")
    };
    assert_eq!(table1.projection, None);
    assert_eq!(table1.encoder_channels, [256, 128, 64]);
    assert_eq!(table1.residual_blocks, 3);
    assert_eq!(table1.decoder_channels, [128, 256]);
    assert!(!table1.mean_offset && !table1.he_init);
    assert!(!paper.mean_offset() && !paper.spectral_only());
    let spectral = cpu.spectral_config().expect("the cpu preset is spectral");
    assert_eq!(
        spectral,
        &SpectralConfig::new(CPU_SPECTRAL_BASIS)
            .with_hidden(Some(CPU_SPECTRAL_HIDDEN))
            .with_he_init(true)
    );
    assert!(cpu.mean_offset() && cpu.spectral_only());
    // The cpu preset holds no convolution widths (they entered its artifact id before).
    let json = cpu.to_string();
    for unused in ["encoder_channels", "projection", "residual_blocks", "convolutional"] {
        assert!(!json.contains(unused), "{json}");
    }
    // Each builds only what it uses: the cpu network is the MLPs (and the zero basis), the
    // paper's is Table 1's ~18 M parameters of convolutions and FCs.
    let model = cpu.init_without_basis(&device()).unwrap();
    assert!(matches!(model, Autoencoder::Spectral(_)));
    let mlp = |a: usize, b: usize| a * b + b;
    let h = CPU_SPECTRAL_HIDDEN;
    let expected = INPUT_VALUES // the offset
        + mlp(96, h) + mlp(h, h) + mlp(h, 10) + mlp(10, h) + mlp(h, h) + mlp(h, 96);
    assert_eq!(model.num_params(), expected);
    paper.validate().unwrap();
    AutoencoderConfig::cpu(40).validate().unwrap();
    assert!(AutoencoderConfig::paper(0).validate().is_err());
    assert!(AutoencoderConfig::cpu(97).validate().is_err(), "k above the basis size");
    assert!(narrow(2, 0, 1, true).validate().is_err());
}

#[test]
fn configurations_round_trip_and_the_flat_format_of_earlier_versions_still_parses() {
    for config in [AutoencoderConfig::paper(5), AutoencoderConfig::cpu(20), narrow(3, 2, 1, true)] {
        let back: AutoencoderConfig = serde_json::from_str(&config.to_string()).unwrap();
        assert_eq!(back, config);
    }
    // `AutoencoderConfig::cpu(10)` as versions before the architecture enum wrote it.
    let flat = r#"{"latent":10,"projection":24,"encoder_channels":[32,48,64],
        "residual_blocks":2,"decoder_channels":[48,32],"negative_slope":0.01,
        "mean_offset":true,"he_init":true,"convolutional":false,"spectral_basis":96,
        "spectral_hidden":256}"#;
    let old: AutoencoderConfig = serde_json::from_str(flat).unwrap();
    assert_eq!(old, AutoencoderConfig::cpu(10));
    // A flat Table 1 (the defaults) and a flat narrow convolutional network.
    let old: AutoencoderConfig = serde_json::from_str(r#"{"latent":7,"projection":null}"#).unwrap();
    assert_eq!(old, AutoencoderConfig::paper(7));
    let flat = r#"{"latent":3,"projection":2,"encoder_channels":[2,2,2],"residual_blocks":1,
        "decoder_channels":[2,2],"mean_offset":true}"#;
    assert_eq!(serde_json::from_str::<AutoencoderConfig>(flat).unwrap(), narrow(3, 2, 1, true));
    // Refused with what to do: the hybrid of an early experiment; a misspelt field.
    let hybrid = r#"{"latent":3,"convolutional":true,"spectral_basis":8,"mean_offset":true}"#;
    let err = serde_json::from_str::<AutoencoderConfig>(hybrid).unwrap_err().to_string();
    assert!(err.contains("no longer supported") && err.contains("train a new model"), "{err}");
    let typo =
        r#"{"latent":3,"architecture":{"spectral":{"directions":8,"hiden":4,"he_init":true}}}"#;
    let err = serde_json::from_str::<AutoencoderConfig>(typo).unwrap_err().to_string();
    assert!(err.contains("unknown field `architecture.spectral.hiden`"), "{err}");
    let unknown = r#"{"latent":3,"architecture":{"recurrent":{}}}"#;
    let err = serde_json::from_str::<AutoencoderConfig>(unknown).unwrap_err().to_string();
    assert!(err.contains("recurrent") && err.contains("convolutional"), "{err}");
}

#[test]
fn shapes_follow_table_1_with_a_narrow_network() {
    let model = narrow(3, 2, 1, true).init_seeded(1, &device()).unwrap();
    assert_eq!(model.latent(), 3);
    let x = Tensor::<4>::ones([1, INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE], &device());
    let z = model.encode(x.clone(), x.clone());
    assert_eq!(z.dims(), [1, 3]);
    let y = model.decode(z);
    assert_eq!(y.dims(), [1, INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE]);
}

#[test]
fn a_fresh_spectral_network_is_its_linear_fit() {
    // Three orthonormal directions (disjoint supports) and an offset, k = 2: before
    // training, encode gives the projections on the first two and decode rebuilds the offset
    // plus their combination; the third direction is what k = 2 loses.
    let config = AutoencoderConfig::spectral(2, 3, Some(4));
    assert!(AutoencoderConfig::spectral(4, 3, None).validate().is_err());
    let third = INPUT_VALUES / 3;
    let mut basis = vec![0f32; 3 * INPUT_VALUES];
    for j in 0..3 {
        let end = if j == 2 { INPUT_VALUES } else { (j + 1) * third };
        let norm = 1.0 / ((end - j * third) as f32).sqrt();
        basis[j * INPUT_VALUES + j * third..j * INPUT_VALUES + end].fill(norm);
    }
    let offset: Vec<f32> = (0..INPUT_VALUES).map(|i| (i % 13) as f32 / 13.0).collect();
    let model = config.init_seeded(5, &device()).unwrap();
    assert!(model.clone().with_basis(basis[1..].to_vec()).is_err());
    let model = model.with_basis(basis.clone()).unwrap().with_offset(&offset).unwrap();
    assert_eq!(model.spectral().map(|p| p.size()), Some(3));
    let (a, b, c) = (3.0f32, -2.0f32, 0.5f32);
    let mix = |c: f32| -> Vec<f32> {
        (0..INPUT_VALUES)
            .map(|i| {
                offset[i]
                    + a * basis[i]
                    + b * basis[INPUT_VALUES + i]
                    + c * basis[2 * INPUT_VALUES + i]
            })
            .collect()
    };
    let shape = [1, INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE];
    let x = Tensor::<4>::from_data(TensorData::new(mix(c), shape), &device());
    let z: Vec<f32> = model.encode(x.clone(), x.ones_like()).into_data().try_into_vec().unwrap();
    assert!((z[0] - a).abs() < 1e-3 && (z[1] - b).abs() < 1e-3, "{z:?}");
    let back = model.decode(Tensor::from_data(TensorData::new(z, [1, 2]), &device()));
    let expected = Tensor::<4>::from_data(TensorData::new(mix(0.0), shape), &device());
    let err: f32 = (back - expected).abs().max().into_scalar();
    assert!(err < 1e-4, "{err}");
}

#[test]
fn offset_is_added_to_the_output_and_rejected_when_absent() {
    let config = narrow(2, 1, 0, true);
    let model = config.init_seeded(2, &device()).unwrap();
    let z = Tensor::<2>::zeros([1, 2], &device());
    let base: Vec<f32> = model.decode(z.clone()).into_data().try_into_vec().unwrap();
    let offset: Vec<f32> = (0..INPUT_VALUES).map(|i| (i % 7) as f32).collect();
    let model = model.with_offset(&offset).unwrap();
    let shifted: Vec<f32> = model.decode(z).into_data().try_into_vec().unwrap();
    for i in [0, 1, 5, 12345, INPUT_VALUES - 1] {
        assert!((shifted[i] - base[i] - offset[i]).abs() < 1e-5, "value {i}");
    }
    assert!(model.with_offset(&[0.0; 3]).is_err());
    let plain = narrow(2, 1, 0, false).init_seeded(2, &device()).unwrap();
    assert!(plain.with_offset(&offset).is_err());
}

#[test]
fn weights_recorded_before_the_architecture_enum_load_after_upgrading_their_paths() {
    // A record whose paths lack the variant name (as earlier versions wrote it) does not load
    // as it is, and loads to the same network once upgraded.
    let config = narrow(2, 1, 1, true);
    let model = config.init_seeded(4, &device()).unwrap();
    let bytes = model.clone().into_record().into_bytes().unwrap().to_vec();
    let old = legacy::tests::strip_variant(&bytes);
    let record = |b: Vec<u8>| {
        burn::store::ModuleRecord::from_bytes(burn::tensor::Bytes::from_bytes_vec(b)).unwrap()
    };
    let fresh = || config.init_seeded(9, &device()).unwrap();
    assert!(fresh().try_load_record(record(old.clone())).is_err());
    let upgraded = legacy::upgrade_record(old, &config).unwrap();
    let loaded = fresh().try_load_record(record(upgraded)).unwrap();
    let z = Tensor::<2>::from_floats([[0.3, -0.7]], &device());
    let a: Vec<f32> = model.decode(z.clone()).into_data().try_into_vec().unwrap();
    let b: Vec<f32> = loaded.decode(z).into_data().try_into_vec().unwrap();
    assert_eq!(a, b);
}
